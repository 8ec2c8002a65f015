// The stereo pass on a known disparity (real Vulkan): two parallel eyes one IPD apart look at a
// fronto-parallel textured plane placed where the disparity is a whole number of pixels, so the
// right eye's image is the left eye's shifted by exactly that many pixels. Each eye's pixel then
// finds its own colour in the other eye, and a correct pass leaves both eyes unchanged whatever
// its beta. A wrong sign, a half-pixel offset or the wrong eye's pose reads a neighbour instead.
#include <cmath>
#include <string>

#include "filter_test_rig.h"

namespace steadyxr::test {
namespace {

constexpr uint32_t kW = 48, kH = 40;
constexpr int kDisparityPx = 3;
constexpr float kIpdM = 0.064f;
constexpr float kHalfFov = 0.6f;                // symmetric, so the principal point is the image centre
constexpr float kNearZ = 0.1f, kFarZ = 100.0f;  // the rig's DepthRef (filter_test_rig.cpp)

// Focal length in pixels and the plane distance whose disparity focal * IPD / z is kDisparityPx.
float focalPx() {
  return float(kW) / (2.0f * std::tan(kHalfFov));
}
float planeDistanceM() {
  return focalPx() * kIpdM / float(kDisparityPx);
}

RefView parallelEye(int e) {
  RefView v;
  v.pose.position = glm::vec3(e == 0 ? -kIpdM / 2 : kIpdM / 2, 0.0f, 0.0f);
  v.fov = {-kHalfFov, kHalfFov, kHalfFov * float(kH) / float(kW), -kHalfFov * float(kH) / float(kW)};
  return v;
}

// The D32 value of distance z: 1/z is linear in the stored depth between 1/near and 1/far.
HostImage planeDepth(float z) {
  const float n = (1.0f / z - 1.0f / kNearZ) / (1.0f / kFarZ - 1.0f / kNearZ);
  return HostImage(kW, kH, glm::vec4(n, 0, 0, 1));
}

// A world point seen at left pixel column u is at right column u - disparity: right(x) =
// left(x + disparity). Both are crops of one wider texture.
Frame planeFrame(bool withDepth) {
  const HostImage wide = pattern(kW + kDisparityPx, kH, 21, 0.25f);
  Frame fr{{HostImage(kW, kH), HostImage(kW, kH)}, {parallelEye(0), parallelEye(1)}};
  for (uint32_t y = 0; y < kH; ++y)
    for (uint32_t x = 0; x < kW; ++x) {
      fr.color[0].at(x, y) = wide.at(x, y);
      fr.color[1].at(x, y) = wide.at(x + kDisparityPx, y);
    }
  if (withDepth) fr.depth = {planeDepth(planeDistanceM()), planeDepth(planeDistanceM())};
  return fr;
}

// Largest RGB difference over the pixels whose partner lies inside the other eye and whose 3x3
// (and steady's footprint filter) does not reach the image border.
float interiorMaxDiff(const HostImage& a, const HostImage& b, int e) {
  float worst = 0.0f;
  const int x0 = e == 0 ? kDisparityPx + 2 : 2, x1 = e == 0 ? int(kW) - 2 : int(kW) - kDisparityPx - 2;
  for (uint32_t y = 2; y + 2 < kH; ++y)
    for (int x = x0; x < x1; ++x)
      for (int k = 0; k < 3; ++k)
        worst = std::max(worst, std::abs(a.at(uint32_t(x), y)[k] - b.at(uint32_t(x), y)[k]));
  return worst;
}

class StereoKnownDisparity : public CoreTest, public ::testing::WithParamInterface<bool> {};

// `stereo` alone (seed 002's beta, floor lowered to 0.5 so a wrong partner shows) against the
// input, and `steady+stereo` (the inverse-variance beta: 1/2 on this exact tap) against steady.
TEST_P(StereoKnownDisparity, EachEyeFindsItsOwnColourInTheOther) {
  const bool withDepth = GetParam();
  core::Params base;
  base.stereoBetaMin = 0.5f;
  base.stereoFarDistanceM = planeDistanceM();  // without depth the far plane is the plane
  const Frame fr = planeFrame(withDepth);
  for (const auto& [method, without] :
       {std::pair<std::string, std::string>{"stereo", "none"}, {"steady+stereo", "steady"}}) {
    auto f = makeFilter(method, base);
    auto g = makeFilter(without, base);
    Rig rig(kW, kH);
    const auto out = rig.run(*f, fr);
    const auto want = rig.run(*g, fr);
    for (int e = 0; e < 2; ++e)
      EXPECT_LE(interiorMaxDiff(out[e], want[e], e), 2e-3f) << method << " eye " << e;
  }
}

// The control: the same eyes with the texture shifted the other way. Were the pass blind to the
// disparity (or the check above unable to fail), this would pass too.
TEST_P(StereoKnownDisparity, AWrongPartnerChangesTheEye) {
  const bool withDepth = GetParam();
  core::Params base;
  base.stereoBetaMin = 0.5f;
  base.stereoFarDistanceM = planeDistanceM();
  Frame fr = planeFrame(withDepth);
  std::swap(fr.color[0], fr.color[1]);  // now right(x) = left(x - disparity): the wrong sign
  auto f = makeFilter("stereo", base);
  auto g = makeFilter("none", base);
  Rig rig(kW, kH);
  const auto out = rig.run(*f, fr);
  const auto want = rig.run(*g, fr);
  for (int e = 0; e < 2; ++e) EXPECT_GT(interiorMaxDiff(out[e], want[e], e), 0.05f) << "eye " << e;
}

INSTANTIATE_TEST_SUITE_P(Depth, StereoKnownDisparity, ::testing::Bool());

// Without depth and with the far plane at 10 m the disparity is known only within focal * IPD *
// (1/0.75 - 1/10) = 2.8 px: steady+stereo blends nowhere, so the stereo pass does not run and the
// output is steady's to the bit (were it run, the frame would pass through the half-float history
// before the 8-bit output and round differently).
class StereoWithoutKnownDisparity : public CoreTest {};

TEST_F(StereoWithoutKnownDisparity, IsSteadyToTheBit) {
  core::Params base;
  base.stereoFarDistanceM = 10.0f;
  ASSERT_GT(focalPx() * kIpdM * (1.0f / base.steadyNearestDepthM - 1.0f / base.stereoFarDistanceM), 1.0f);
  Frame fr = planeFrame(false);
  for (auto& c : fr.color)
    for (auto& px : c.px) px = glm::vec4(glm::vec3(px) * 0.7f + 0.013f, 1.0f);  // off the 8-bit grid
  auto f = makeFilter("steady+stereo", base);
  auto g = makeFilter("steady", base);
  Rig rigF(kW, kH, VK_FORMAT_R16G16B16A16_SFLOAT, VK_FORMAT_R8G8B8A8_UNORM);
  Rig rigG(kW, kH, VK_FORMAT_R16G16B16A16_SFLOAT, VK_FORMAT_R8G8B8A8_UNORM);
  for (int frame = 0; frame < 3; ++frame) {
    const auto out = rigF.run(*f, fr);
    const auto want = rigG.run(*g, fr);
    for (int e = 0; e < 2; ++e)
      EXPECT_EQ(compare(out[e], want[e]).maxAbs, 0.0f) << "frame " << frame << " eye " << e;
  }
}

// Half a pixel of disparity: the right eye's partner of a left pixel lies between two texels, and
// a bilinear tap there returns c + (1/2) f(1-f) c" (f = 1/2), a blur. A smooth grating
// c(x) = 0.5 + 0.25 sin(2 pi x / 8 px) along x, sampled at the pixel centres, right(x) = c(x + 2.5)
// where left(x) = c(x). steady+stereo with the curvature correction finds each eye's own value to
// fourth order (relative error 1 - cos(pi/8) - (1 - cos(pi/4))/4 = 0.3 %); without it the tap's
// blur (1 - cos(pi/8) = 7.6 % of the amplitude) goes into both eyes with weight 1 - beta.
constexpr float kHalfPixelDisparity = 2.5f;
constexpr float kGratingPeriodPx = 8.0f;

Frame gratingFrame() {
  Frame fr{{HostImage(kW, kH), HostImage(kW, kH)}, {parallelEye(0), parallelEye(1)}};
  const float omega = 2.0f * 3.14159265f / kGratingPeriodPx;
  for (uint32_t y = 0; y < kH; ++y)
    for (uint32_t x = 0; x < kW; ++x)
      for (int e = 0; e < 2; ++e) {
        const float u = float(x) + (e == 0 ? 0.0f : kHalfPixelDisparity);
        fr.color[e].at(x, y) = glm::vec4(glm::vec3(0.5f + 0.25f * std::sin(omega * u)), 1.0f);
      }
  const float z = focalPx() * kIpdM / kHalfPixelDisparity;
  fr.depth = {planeDepth(z), planeDepth(z)};
  return fr;
}

float interiorMaxDiffMargin(const HostImage& a, const HostImage& b, int margin) {
  float worst = 0.0f;
  for (uint32_t y = 2; y + 2 < kH; ++y)
    for (int x = margin; x < int(kW) - margin; ++x)
      for (int k = 0; k < 3; ++k)
        worst = std::max(worst, std::abs(a.at(uint32_t(x), y)[k] - b.at(uint32_t(x), y)[k]));
  return worst;
}

class StereoHalfPixelDisparity : public CoreTest {};

TEST_F(StereoHalfPixelDisparity, TheTapsBlurIsTakenOff) {
  const Frame fr = gratingFrame();
  float worst[2] = {};  // with, without the correction
  for (int corrected = 1; corrected >= 0; --corrected) {
    core::Params base;
    base.stereoTapCurvature = corrected != 0;
    auto f = makeFilter("steady+stereo", base);
    auto g = makeFilter("steady", base);
    Rig rig(kW, kH);
    const auto out = rig.run(*f, fr);
    const auto want = rig.run(*g, fr);
    for (int e = 0; e < 2; ++e)
      worst[corrected] = std::max(worst[corrected], interiorMaxDiffMargin(out[e], want[e], 5));
  }
  EXPECT_LE(worst[1], 1.5e-3f) << "corrected tap";
  EXPECT_GT(worst[0], 4e-3f) << "the raw tap's blur shows (the check can fail)";
}

}  // namespace
}  // namespace steadyxr::test
