// Params::steadyResolvedEdges (round 48, README item 15) on real Vulkan: beside a geometric edge that the
// app resolved with MSAA (the edge pixel one mix of the two flat sides, a depth edge), the default shows the
// app's sample instead of a history that its resampling blurred; a 1-sample render's aliased edge, a
// texture's mixed step on one surface and a frame without depth are filtered as without the item.
#include <gtest/gtest.h>

#include <cmath>
#include <glm/gtc/quaternion.hpp>
#include <optional>
#include <random>

#include "filter_test_rig.h"
#include "reference.h"

using namespace steadyxr;
using namespace steadyxr::core;
using namespace steadyxr::test;

namespace {

constexpr uint32_t kSize = 48;
const glm::vec3 kNearSide(0.05f, 0.08f, 0.12f), kFarSide(0.60f, 0.45f, 0.25f);  // linear, two hues
constexpr float kNearM = 0.5f, kFarM = 3.0f;

// A straight edge fixed in the world (directions, so a head rotation moves it on screen), tilted against
// the pixel grid: the near surface left of it, the far one right. u, v: the ray's azimuth and elevation in
// centre pixels.
bool onFarSide(const RefView& view, float px, float py) {
  const glm::vec3 eyeDir(2.0f * px / float(kSize) - 1.0f, 1.0f - 2.0f * py / float(kSize), -1.0f);
  const glm::vec3 world = view.pose.orientation * glm::normalize(eyeDir);
  const float pxPerRad = float(kSize) / 2.0f;  // Fov{} (+-45 deg)
  const float u = std::atan2(world.x, -world.z) * pxPerRad;
  const float v = std::asin(glm::clamp(world.y, -1.0f, 1.0f)) * pxPerRad;
  return u - 0.3f * v > 0.37f;
}

enum class Render { OneSample, Msaa4, Truth };

// The app's image: each pixel's centre (1-sample), the mean in linear light of 4x MSAA's rotated-grid
// samples (what a resolve writes), or of 8 x 8 samples (the ground truth). `oneSurface`: both sides at the
// near surface's depth (a texture's step on one plane). Depth: the surface at the pixel's centre.
Frame render(const RefView& view, Render how, bool oneSurface = false) {
  static const glm::vec2 kMsaa4[4] = {
      {-2.0f / 16, -6.0f / 16}, {6.0f / 16, -2.0f / 16}, {-6.0f / 16, 2.0f / 16}, {2.0f / 16, 6.0f / 16}};
  HostImage img(kSize, kSize), depth(kSize, kSize);
  for (uint32_t y = 0; y < kSize; ++y)
    for (uint32_t x = 0; x < kSize; ++x) {
      const float cx = float(x) + 0.5f, cy = float(y) + 0.5f;
      // A pixel whose four corners lie on one side of the (nearly straight) edge lies on it whole: only the
      // pixels it crosses take their samples (the host's share of the test, in the sanitizers' Debug build).
      int cornersFar = 0;
      for (int k = 0; k < 4; ++k)
        cornersFar += onFarSide(view, float(x + uint32_t(k & 1)), float(y + uint32_t(k >> 1)));
      const bool crossed = cornersFar != 0 && cornersFar != 4;
      float far = cornersFar == 4 ? 1.0f : 0.0f;
      if (how == Render::OneSample) far = onFarSide(view, cx, cy) ? 1.0f : 0.0f;
      if (how == Render::Msaa4 && crossed) {
        far = 0.0f;
        for (const glm::vec2 s : kMsaa4) far += onFarSide(view, cx + s.x, cy + s.y) ? 0.25f : 0.0f;
      }
      if (how == Render::Truth && crossed) {
        far = 0.0f;
        for (int k = 0; k < 64; ++k)
          far += onFarSide(view, float(x) + (float(k % 8) + 0.5f) / 8.0f,
                           float(y) + (float(k / 8) + 0.5f) / 8.0f)
                     ? 1.0f / 64.0f
                     : 0.0f;
      }
      img.at(x, y) = glm::vec4(glm::mix(kNearSide, kFarSide, far), 1.0f);
      const float z = !oneSurface && onFarSide(view, cx, cy) ? kFarM : kNearM;
      depth.at(x, y).r =
          (1.0f / z - 1.0f / 0.1f) / (1.0f / 100.0f - 1.0f / 0.1f);  // D32 of near 0.1, far 100
    }
  Frame fr;
  fr.color = {img, img};
  fr.views = {view, view};
  fr.depth = {depth, depth};
  return fr;
}

Params steadyWith(bool resolvedEdges) {
  Params p = *applyMethodName("steady");
  p.steadyResolvedEdges = resolvedEdges;
  return p;
}

// Sub-pixel yaw/pitch tremor (uniform, +-0.4 px at the centre), the same for every run.
std::vector<RefView> tremor(int frames) {
  std::mt19937 rng(11);
  const float pxDeg = std::atan(2.0f / float(kSize)) / kDeg;
  std::uniform_real_distribution<float> offset(-0.4f * pxDeg, 0.4f * pxDeg);
  std::vector<RefView> views(static_cast<size_t>(frames));
  for (RefView& view : views) {
    view.fov = Fov{};
    view.pose.orientation = glm::angleAxis(offset(rng) * kDeg, glm::vec3(0, 1, 0)) *
                            glm::angleAxis(offset(rng) * kDeg, glm::vec3(1, 0, 0));
  }
  return views;
}

struct Run {
  std::vector<HostImage> outputs, inputs;
  double rmseToTruth = 0.0, inputRmseToTruth = 0.0;  // over the last half of the frames
};

// `how` rendered under the tremor through steady with item 15 on or off; withDepth = false: no depth given.
std::optional<Run> runUnderTremor(Render how, bool resolvedEdges, bool oneSurface = false,
                                  bool withDepth = true, int frames = 24) {
  auto f = makeFilter("steady", steadyWith(resolvedEdges));
  if (!f) return std::nullopt;
  Rig rig(kSize, kSize);
  Run run;
  const std::vector<RefView> views = tremor(frames);
  for (int k = 0; k < frames; ++k) {
    Frame fr = render(views[size_t(k)], how, oneSurface);
    if (!withDepth) fr.depth = {};
    const auto out = rig.run(*f, fr, 1);
    run.outputs.push_back(out[0]);
    run.inputs.push_back(fr.color[0]);
    if (k >= frames / 2) {
      const HostImage truth = render(views[size_t(k)], Render::Truth).color[0];
      run.rmseToTruth += rmse(out[0], truth) / double(frames - frames / 2);
      run.inputRmseToTruth += rmse(fr.color[0], truth) / double(frames - frames / 2);
    }
  }
  return run;
}

}  // namespace

// Over an MSAA app's resolved edge the default with item 15 is no worse than the app's own image, and
// better than without it (whose history, resampled under the tremor, blurs the edge into its ring).
TEST_F(CoreTest, SteadyResolvedEdgeKeepsAnMsaaAppsEdge) {
  const auto with = runUnderTremor(Render::Msaa4, true), without = runUnderTremor(Render::Msaa4, false);
  ASSERT_TRUE(with && without) << "filter creation failed";
  // Measured (lavapipe): the app's image 0.00546 of RMSE against the 8 x 8 truth, 0.00579 without the item
  // (above it: the case the item is for), 0.00520 with it.
  EXPECT_GT(without->rmseToTruth, with->inputRmseToTruth)
      << "without the item the edge should break the promise";
  EXPECT_LE(with->rmseToTruth, with->inputRmseToTruth)
      << "with item 15 " << with->rmseToTruth << ", the app's image " << with->inputRmseToTruth;
  EXPECT_LT(with->rmseToTruth, 0.95 * without->rmseToTruth)
      << "with item 15 " << with->rmseToTruth << ", without " << without->rmseToTruth;
}

// The shader against the CPU reference (steady_reference.cpp, written from the README's item 15) frame by
// frame on the MSAA render, where the item acts on the edge's ring.
TEST_F(CoreTest, SteadyResolvedEdgeMatchesReference) {
  const Params p = steadyWith(true);
  auto f = makeFilter("steady", p);
  ASSERT_TRUE(f);
  Rig rig(kSize, kSize);
  const std::vector<RefView> views = tremor(8);
  HostImage hist(kSize, kSize);
  RefView prev = views[0];
  int pixelsOff = 0, ringPixels = 0, ringKept = 0;
  for (int k = 0; k < 8; ++k) {
    const Frame fr = render(views[size_t(k)], Render::Msaa4);
    const HostImage& in = fr.color[0];
    const auto out = rig.run(*f, fr, 1);
    const HostImage want =
        toHalf(steadyRef(p, toHalf(in), hist, k > 0, prev, fr.views[0], &fr.depth[0], 0.1f, 100.0f));
    for (uint32_t y = 0; y < kSize; ++y)
      for (uint32_t x = 0; x < kSize; ++x) {
        const glm::vec3 d = glm::abs(glm::vec3(out[0].at(x, y)) - glm::vec3(want.at(x, y)));
        pixelsOff += std::max({d.r, d.g, d.b}) > 0.004f ? 1 : 0;
        // A ring pixel: the near side's colour, the mixed edge pixel or the far side to its right.
        const bool ring =
            k > 0 && in.at(x, y) == in.at(0, y) && in.at(std::min(x + 1, kSize - 1), y) != in.at(x, y);
        const glm::vec3 fromInput = glm::abs(glm::vec3(want.at(x, y)) - glm::vec3(in.at(x, y)));
        ringPixels += ring ? 1 : 0;
        ringKept += ring && std::max({fromInput.r, fromInput.g, fromInput.b}) < 1e-3f ? 1 : 0;
      }
    hist = want;
    prev = fr.views[0];
  }
  // Measured (lavapipe): 7 pixels of 8 x 48 x 48 off by more than 0.004 (bilinear weights of 8 sub-texel
  // bits on a step of 0.5; a few decisions on a boundary), all in the last frame. Planted: with the
  // coverage's lower bound planted at 0.3 instead of 1/8, 99. The reference keeps this frame's sample at 233
  // of the ring's 336 pixels (the rest: a neighbour along the edge that is not flat, the staircase's
  // corners).
  EXPECT_LE(pixelsOff, 16) << "pixels off the reference by more than 0.004 over 8 frames";
  EXPECT_GT(ringKept, ringPixels / 2)
      << ringKept << " of " << ringPixels << " ring pixels kept the app's sample";
}

// A 1-sample render's aliased edge has no mixed pixel: nothing changes with the item, to the bit. Nor where
// the mixed step lies on one surface (a filtered texture's), nor where the app gives no depth.
TEST_F(CoreTest, SteadyResolvedEdgeLeavesOtherEdgesAsTheyWere) {
  struct Case {
    const char* what;
    Render how;
    bool oneSurface, withDepth;
  };
  for (const Case c : {Case{"a 1-sample edge", Render::OneSample, false, true},
                       Case{"a mixed step on one surface", Render::Msaa4, true, true},
                       Case{"no depth", Render::Msaa4, false, false}}) {
    const auto with = runUnderTremor(c.how, true, c.oneSurface, c.withDepth, 8);
    const auto without = runUnderTremor(c.how, false, c.oneSurface, c.withDepth, 8);
    ASSERT_TRUE(with && without) << "filter creation failed";
    for (size_t k = 0; k < with->outputs.size(); ++k)
      EXPECT_EQ(compare(with->outputs[k], without->outputs[k]).maxAbs, 0.0f) << c.what << ", frame " << k;
  }
}
