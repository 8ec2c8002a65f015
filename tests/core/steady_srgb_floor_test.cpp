// Params::steadyClipQuantSrgb on real Vulkan: the clip box's floor, half a step of the 8-bit sRGB
// input at the level. A dark fade up is followed (a linear half step would be codes wide there), UNORM
// input keeps the linear floor, and a flat field one code off its history never leaves half a code of
// what the device reads, so the output rounds back to the input's own code.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>

#include "filter_test_rig.h"
#include "reference.h"

using namespace steadyxr;
using namespace steadyxr::core;
using namespace steadyxr::test;

namespace {

// Linear light of 8-bit sRGB code `code`.
double codeToLinear(int code) {
  return srgbDecode(code / 255.0);
}

// Params::steadyClipQuantSrgb: a flat dark field (sRGB code 39, linear 0.02: the fade scene's
// background at 15 % light) held for 16 frames, then brightening by one code a frame (the start of
// a fade up) for 8 frames, fed as `format` (sRGB: the pass sees linear light; UNORM: the codes).
// How many codes the centre pixel's output lags behind at the end, the largest difference of any
// output pixel from the CPU reference (steadyRef, given the floor the input format calls for), and
// the outputs of the last frame.
struct DarkFadeUp {
  double lagCodes = 0.0;
  float maxRefDiff = 0.0f;
  HostImage last;
};
std::optional<DarkFadeUp> darkFadeUp(bool quantSrgb, VkFormat format = VK_FORMAT_R8G8B8A8_SRGB) {
  const uint32_t W = 16, H = 16;
  const bool srgb = format == VK_FORMAT_R8G8B8A8_SRGB;
  Params p = steadyBoxAlone();
  p.steadyClipQuantSrgb = quantSrgb;
  auto f = makeFilter("steady", p), copy = makeFilter("none");
  if (!f || !copy) return std::nullopt;
  const auto valueOf = [srgb](int code) { return srgb ? codeToLinear(code) : code / 255.0; };
  // The reference starts from the input as the pass reads it (lavapipe's sRGB decode is within
  // about 1 % of IEC 61966-2-1's near black): the copy pass's output.
  Rig rig(W, H, format), copyRig(W, H, format);
  DarkFadeUp r;
  HostImage hist;
  for (int k = 0; k < 24; ++k) {
    const int code = 39 + std::max(0, k - 15);
    const float v = float(valueOf(code));
    HostImage img(W, H);
    for (auto& px : img.px) px = glm::vec4(v, v, v, 1.0f);
    const Frame frame{{img, img}, {eye(0, 0), eye(0, 0)}};
    const auto out = rig.run(*f, frame, 1);
    const HostImage read = copyRig.run(*copy, frame, 1)[0];
    const HostImage ref = toHalf(
        steadyRef(p, toHalf(read), hist, k > 0, eye(0, 0), eye(0, 0), nullptr, 0.1f, 100.0f, {}, srgb));
    for (size_t i = 0; i < ref.px.size(); ++i)
      for (int ch = 0; ch < 3; ++ch)
        r.maxRefDiff = std::max(r.maxRefDiff, std::abs(out[0].px[i][ch] - ref.px[i][ch]));
    hist = ref;
    r.lagCodes = (double(read.at(W / 2, H / 2).g) - double(out[0].at(W / 2, H / 2).g)) /
                 (valueOf(code) - valueOf(code - 1));
    r.last = out[0];
  }
  return r;
}

}  // namespace

// On a flat field the box is only its floor: half an 8-bit step in linear light is four sRGB codes
// wide at linear 0.02, so a history a code or two behind is kept; half an sRGB code at the level
// clips it every frame and the output follows. Both match the CPU reference written from the rule.
TEST_F(CoreTest, SteadySrgbQuantFloorFollowsADarkFadeUp) {
  const std::optional<DarkFadeUp> linearFloor = darkFadeUp(false), srgbFloor = darkFadeUp(true);
  ASSERT_TRUE(linearFloor && srgbFloor) << "filter creation failed";
  // Measured (lavapipe): 1.17 codes behind with the linear floor, 0.15 with the sRGB one.
  EXPECT_GT(linearFloor->lagCodes, 0.8) << "the linear floor should keep the lag here";
  EXPECT_LT(srgbFloor->lagCodes, 0.5) << "linear floor " << linearFloor->lagCodes << " codes";
  // A code is ~1e-3 here; half precision holds ~1.5e-5 at 0.02.
  EXPECT_LT(linearFloor->maxRefDiff, 1e-4f);
  EXPECT_LT(srgbFloor->maxRefDiff, 1e-4f);
}

// UNORM input is filtered in its codes, where a step is the linear floor's: the sRGB floor must
// not apply there (at code 39 it would be narrower than a code), so the switch changes nothing.
TEST_F(CoreTest, SteadySrgbQuantFloorLeavesUnormInputAlone) {
  const auto off = darkFadeUp(false, VK_FORMAT_R8G8B8A8_UNORM),
             on = darkFadeUp(true, VK_FORMAT_R8G8B8A8_UNORM);
  ASSERT_TRUE(off && on) << "filter creation failed";
  EXPECT_EQ(compare(on->last, off->last).maxAbs, 0.0f);
  EXPECT_LT(on->maxRefDiff, 1e-4f);
}

namespace {

// 8-bit sRGB code of linear `l`, unrounded.
double linearToCode(double l) {
  return 255.0 * srgbEncode(l);
}

// The codes one half-precision ulp spans at linear `l`: the RGBA16F readbacks below round the output
// and the input each by up to half of one (0.03 of a code each at the top codes).
double halfPrecisionUlpCodes(double l) {
  const double ulp = std::ldexp(1.0, std::max(std::ilogb(std::max(l, 1e-8)), -14) - 10);
  return linearToCode(l + ulp) - linearToCode(l);
}

struct FlatStep {
  double worstBeyondReadback = 0;  // codes from the input, less what the readbacks can account for
  int worstCode = 0;
  double worstCodes = 0;  // the distance there, as read
};

// Stripes 4 px wide, one per code c in 1..254, held at code c + historyOffset for 20 frames, then
// one frame at c: the flat 3x3s inside each stripe (x % 4 of 1 and 2) see only their floor. How far,
// in codes, the output lies from the input as the device reads it (the copy pass: lavapipe's sRGB
// decode is off IEC's by up to a third of a code), the largest over the stripes. RGBA16F output, so
// the distance is not hidden by the output's own rounding; its own rounding is allowed for.
std::optional<FlatStep> flatStepCodes(int historyOffset) {
  constexpr int kCodes = 254, kStripe = 4;
  const uint32_t W = kCodes * kStripe, H = 4;
  auto f = makeFilter("steady", steadyBoxAlone()), copy = makeFilter("none");
  if (!f || !copy) return std::nullopt;
  const auto field = [&](int offset) {
    HostImage img(W, H);
    for (uint32_t y = 0; y < H; ++y)
      for (uint32_t x = 0; x < W; ++x) {
        const float v = float(codeToLinear(int(x) / kStripe + 1 + offset));
        img.at(x, y) = glm::vec4(v, v, v, 1.0f);
      }
    return img;
  };
  Rig rig(W, H, VK_FORMAT_R8G8B8A8_SRGB, VK_FORMAT_R16G16B16A16_SFLOAT),
      copyRig(W, H, VK_FORMAT_R8G8B8A8_SRGB, VK_FORMAT_R16G16B16A16_SFLOAT);
  const HostImage before = field(historyOffset), after = field(0);
  for (int k = 0; k < 20; ++k) rig.run(*f, Frame{{before, before}, {eye(0, 0), eye(0, 0)}}, 1);
  const Frame step{{after, after}, {eye(0, 0), eye(0, 0)}};
  const HostImage out = rig.run(*f, step, 1)[0], read = copyRig.run(*copy, step, 1)[0];
  FlatStep worst;
  for (uint32_t x = 0; x < W; ++x) {
    if (x % kStripe == 0 || x % kStripe == 3) continue;  // the 3x3 reaches the next stripe
    for (uint32_t y = 0; y < H; ++y) {
      const double o = out.at(x, y).g, i = read.at(x, y).g;
      const double codes = std::abs(linearToCode(o) - linearToCode(i));
      const double beyond = codes - halfPrecisionUlpCodes(std::max(o, i));
      if (beyond > worst.worstBeyondReadback) worst = {beyond, int(x) / kStripe + 1, codes};
    }
  }
  return worst;
}

}  // namespace

// A flat 3x3 has no spread and no curvature: the box is its floor alone. A history one code off (the
// first frame of a fade, whose step no single pixel can tell from rounding) is clipped onto that floor,
// and the output must still round to the input's code: the floor stays under half a code at every
// level. Round 8's gamma-2 slope made it up to 0.71 of a code in the dark (codes 10-60).
TEST_F(CoreTest, SteadySrgbQuantFloorStaysWithinHalfACode) {
  for (int offset : {1, -1}) {
    const std::optional<FlatStep> step = flatStepCodes(offset);
    ASSERT_TRUE(step) << "filter creation failed";
    std::printf(
        "history %+d code: the output %.3f codes from the input at code %d (%.3f beyond the readback's "
        "rounding)\n",
        offset, step->worstCodes, step->worstCode, step->worstBeyondReadback);
    EXPECT_LT(step->worstBeyondReadback, 0.5)
        << "history " << offset << " code(s) off the input: " << step->worstCodes << " codes from it at code "
        << step->worstCode;
  }
}
