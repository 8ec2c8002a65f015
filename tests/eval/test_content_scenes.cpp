// The scenes whose content changes in place (scene.h, scene_video.cpp): the video's picture steps at
// its 24 fps content rate and not between, a cut changes the picture, the fade dims the whole view
// and flashes, the light blinks at 2 Hz, and each reports its changes (for recovery) where they are.
#include "eye_rig.h"
#include "scene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace steadyxr::eval {
namespace {

// Four textures: white (index 0), the picture, and the two the video may cut to.
TextureSet textures() {
  TextureSet t;
  for (const char* name : {"white", "astronaut", "coffee", "camera"}) {
    Rgba8 img;
    img.width = img.height = 4;
    img.pixels.assign(4 * 4 * 4, 128);
    t.images.push_back(img);
    t.names.push_back(name);
  }
  return t;
}

Scene contentScene(const std::string& name, double ppd = 0.0) {
  Scene s;
  std::string error;
  EXPECT_TRUE(makeScene(name, "astronaut", textures(), ppdTangentScale(ppd, 96), HeadPose{}, &s, &error))
      << error;
  return s;
}

bool sameDraws(const DrawList& a, const DrawList& b) {
  if (a.quads.size() != b.quads.size() || a.clearColor != b.clearColor) return false;
  for (size_t i = 0; i < a.quads.size(); ++i) {
    const DrawQuad &p = a.quads[i], &q = b.quads[i];
    if (p.model != q.model || p.texture != q.texture || p.tint != q.tint || p.uvST != q.uvST) return false;
  }
  return true;
}

TEST(ContentScenes, AreKnownScenes) {
  for (const char* name : {"video", "fade", "blink"}) {
    EXPECT_TRUE(isContentScene(name));
    EXPECT_NE(std::find(sceneNames().begin(), sceneNames().end(), name), sceneNames().end()) << name;
  }
  EXPECT_FALSE(isContentScene("imageviewer"));
  EXPECT_FALSE(bool(contentScene("imageviewer").contentChanges));  // the old scenes report none
}

// At 90 Hz a 24 fps frame spans 3.75 app frames: app frames within one content frame draw the same,
// the first app frame of the next content frame draws something else (the pan and zoom moved).
TEST(ContentScenes, VideoStepsAtTheContentRateOnly) {
  const Scene s = contentScene("video");
  const double appDt = 1.0 / 90.0;
  int steps = 0, sameWithin = 0;
  for (int f = 1; f < 90; ++f) {
    const double t0 = (f - 1) * appDt, t1 = f * appDt;
    const bool newContentFrame = videoContentFrame(t1) != videoContentFrame(t0);
    const bool same = sameDraws(s.drawsAt(t0), s.drawsAt(t1));
    EXPECT_EQ(same, !newContentFrame) << "app frames " << f - 1 << ", " << f;
    steps += newContentFrame;
    sameWithin += same;
  }
  EXPECT_EQ(steps, 23);  // 1 s of 24 fps content seen from t = 1/90 s on: frames 1..23
  EXPECT_GT(sameWithin, 60);
  // The content frame is floor(24 t): at 1/24 s exactly the next one, just before it not.
  EXPECT_EQ(videoContentFrame(1.0 / 24.0), 1);
  EXPECT_EQ(videoContentFrame(1.0 / 24.0 - 1e-6), 0);
}

// Every 0.5 s a cut to the other picture; both shots move on screen (Ken Burns zoom and pan, fast pan).
TEST(ContentScenes, VideoCutsToAnotherPictureEveryHalfSecond) {
  const Scene s = contentScene("video");
  const uint32_t picture = textures().find("astronaut");
  EXPECT_EQ(s.drawsAt(0.1).quads.at(0).texture, picture);
  EXPECT_NE(s.drawsAt(0.6).quads.at(0).texture, picture);
  EXPECT_EQ(s.drawsAt(1.1).quads.at(0).texture, picture);
  // The slow shot's pan per content frame is sub-pixel, the fast one's several pixels (on a 39 px
  // picture at 96 px, scene_video.cpp): uv offset per content frame over the shown scale.
  auto panPx = [&](double t) {
    const glm::vec4 a = s.drawsAt(t).quads[0].uvST, b = s.drawsAt(t + 1.0 / 24.0).quads[0].uvST;
    const double centreShift = 0.5 * (a.x - b.x);  // the zoom's recentring
    return std::fabs((b.z - a.z) - centreShift) / a.x * 39.0;
  };
  EXPECT_LT(panPx(0.1), 1.0);
  EXPECT_GT(panPx(0.1), 0.1);
  EXPECT_GT(panPx(0.6), 2.0);
  const std::vector<double> cuts = s.contentChanges(0.0, 1.2);
  ASSERT_EQ(cuts.size(), 3u);
  EXPECT_DOUBLE_EQ(cuts[1], 0.5);
  EXPECT_DOUBLE_EQ(cuts[2], 1.0);
}

// The fade dims the picture and the background together to 15 %, comes back, and flashes.
TEST(ContentScenes, FadeDimsTheWholeViewAndFlashes) {
  const Scene s = contentScene("fade");
  const DrawList full = s.drawsAt(0.1), low = s.drawsAt(0.9), mid = s.drawsAt(0.5), flash = s.drawsAt(1.72);
  EXPECT_FLOAT_EQ(full.quads[0].tint.r, 1.0f);
  EXPECT_NEAR(low.quads[0].tint.r, 0.15f, 1e-6f);
  EXPECT_NEAR(low.clearColor.r, 0.15f * full.clearColor.r, 1e-6f);
  EXPECT_GT(mid.quads[0].tint.r, 0.15f);
  EXPECT_LT(mid.quads[0].tint.r, 1.0f);
  EXPECT_GT(flash.quads[0].tint.r, 1.5f);
  EXPECT_FLOAT_EQ(s.drawsAt(1.8).quads[0].tint.r, 1.0f);
  EXPECT_TRUE(sameDraws(s.drawsAt(0.1), s.drawsAt(2.1)));  // periodic, 2 s
  EXPECT_EQ(s.contentChanges(0.0, 2.0).size(), 6u);        // 0.2, 0.8, 1.0, 1.5, 1.7, 1.75
}

// The light is on for 0.25 s and off for 0.25 s; on the picture plane, also under --ppd.
TEST(ContentScenes, BlinkSwitchesAtTwoHertz) {
  for (double ppd : {0.0, 20.0}) {
    const Scene s = contentScene("blink", ppd);
    EXPECT_EQ(s.drawsAt(0.1).quads.size(), 1u);
    EXPECT_EQ(s.drawsAt(0.3).quads.size(), 2u);
    EXPECT_EQ(s.drawsAt(0.6).quads.size(), 1u);
    const DrawList on = s.drawsAt(0.3);
    // 2 mm (scaled) in front of the picture, never behind it.
    EXPECT_GT(on.quads[1].model[3].z, on.quads[0].model[3].z);
    EXPECT_EQ(s.contentChanges(0.0, 1.0).size(), 5u);
  }
}

}  // namespace
}  // namespace steadyxr::eval
