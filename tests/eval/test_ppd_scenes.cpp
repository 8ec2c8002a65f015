// --ppd for the scenes in metres (scene.h, makeScene; eye_rig.h, ppdDepthStretch), checked by
// what it must do to pixels: from the first frame's head every corner of every quad lands on the
// pixel it has without --ppd, in both eyes; a sideways head translation keeps that; a scene the
// stretch puts beyond the far plane is refused.
#include "eye_rig.h"
#include "scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include <glm/gtc/quaternion.hpp>

namespace steadyxr::eval {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

// A start pose off the origin and turned a little (the corpus motions' first poses are near, not
// at, the origin): the stretch must be about this head, not about the world's axes.
HeadPose offsetStartHead() {
  HeadPose head;
  head.position = glm::vec3(0.03f, -0.02f, 0.05f);
  head.orientation = glm::angleAxis(float(2.0 * kDegToRad), glm::normalize(glm::vec3(0.3f, 1.0f, 0.1f)));
  return head;
}

Scene sceneAt(const std::string& name, double tangentScale, const HeadPose& start) {
  Scene scene;
  std::string error;
  EXPECT_TRUE(makeScene(name, "", TextureSet{}, tangentScale, start, &scene, &error)) << error;
  return scene;
}

// Every quad corner of `name` at time t, seen by `viewer` with and without --ppd `ppd`: the same
// pixel in both eyes.
void expectSamePixels(const std::string& name, double ppd, int w, const HeadPose& start,
                      const HeadPose& viewer, double tSec) {
  const double scale = ppdTangentScale(ppd, w);
  const Scene wide = sceneAt(name, 1.0, start), narrow = sceneAt(name, scale, start);
  const auto wideQuads = wide.drawsAt(tSec).quads, narrowQuads = narrow.drawsAt(tSec).quads;
  ASSERT_EQ(wideQuads.size(), narrowQuads.size());
  ASSERT_FALSE(wideQuads.empty());
  const auto wideCams = eyeCameras(viewer, w, w, EyeRig{0.0}),
             narrowCams = eyeCameras(viewer, w, w, EyeRig{ppd});
  int seen = 0;
  for (size_t q = 0; q < wideQuads.size(); ++q) {
    for (const glm::vec2 corner : {glm::vec2(-0.5f), glm::vec2(0.5f), glm::vec2(-0.5f, 0.5f)}) {
      const glm::vec4 local(corner, 0.0f, 1.0f);
      for (int eye = 0; eye < 2; ++eye) {
        glm::vec2 a, b;
        float depthA = 0, depthB = 0;
        const bool inA = project(wideCams[eye], glm::vec3(wideQuads[q].model * local), &a, &depthA);
        const bool inB = project(narrowCams[eye], glm::vec3(narrowQuads[q].model * local), &b, &depthB);
        ASSERT_EQ(inA, inB) << name << " quad " << q;
        if (!inA) continue;
        ++seen;
        // 1e-2 px: float matrices at up to 60 m (the fence wires are 6 mm, ~0.1 px without --ppd).
        EXPECT_NEAR(b.x, a.x, 1e-2 + 1e-5 * std::fabs(a.x)) << name << " quad " << q << " eye " << eye;
        EXPECT_NEAR(b.y, a.y, 1e-2 + 1e-5 * std::fabs(a.y)) << name << " quad " << q << " eye " << eye;
      }
    }
  }
  EXPECT_GT(seen, 0) << name;
}

TEST(EvalPpdScenes, StillHeadSeesThePixelsItSeesWithoutPpd) {
  for (const char* name : {"thin", "moving", "disocclusion"}) {
    for (const HeadPose& start : {HeadPose{}, offsetStartHead()}) {
      // 96 px at 10 ppd (tangent scale 0.085) and 256 px at 20 ppd (0.114): both fit the far plane.
      expectSamePixels(name, 10.0, 96, start, start, 0.0);
      expectSamePixels(name, 20.0, 256, start, start, 0.7);  // the moving picture elsewhere on its path
    }
  }
}

TEST(EvalPpdScenes, SidewaysHeadTranslationKeepsItsPixels) {
  // The stretch keeps the lateral axes, so a sideways step (disocclusion's sway, 0.1 m) moves every
  // point by the pixels it moves without --ppd: the parallax is kept.
  const HeadPose start = offsetStartHead();
  HeadPose stepped = start;
  stepped.position += start.orientation * glm::vec3(0.1f, 0.0f, 0.0f);
  for (const char* name : {"thin", "moving", "disocclusion"})
    expectSamePixels(name, 20.0, 256, start, stepped, 0.3);
}

TEST(EvalPpdScenes, RefusedBeyondTheFarPlane) {
  // thin's text page at 5 m / (0.85 / 20) = 117 m at 96 px, 20 ppd: beyond 0.9 x 100 m.
  Scene scene;
  std::string error;
  EXPECT_FALSE(makeScene("thin", "", TextureSet{}, ppdTangentScale(20.0, 96), HeadPose{}, &scene, &error));
  EXPECT_NE(error.find("far plane"), std::string::npos) << error;
  // moving's wall at 2.5 m / 0.0426 = 59 m fits.
  EXPECT_TRUE(makeScene("moving", "", TextureSet{}, ppdTangentScale(20.0, 96), HeadPose{}, &scene, &error));
}

}  // namespace
}  // namespace steadyxr::eval
