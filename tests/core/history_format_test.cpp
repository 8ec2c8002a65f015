// The 8-bit history (Params::historyFormat, common.glsl storeHistory) on real Vulkan (lavapipe)
// with validation: a dark gradient accumulated over 64 frames of head tremor must come out without
// the banding a stalled 8-bit history leaves, as the RGBA16F history does.
//
// The app renders the gradient into 8-bit sRGB with its own per-frame dither (as renderers do to
// hide banding), so the truth is recoverable only by averaging frames: each input pixel is the
// gradient's level rounded up with the probability of its fraction. The filter's output is
// RGBA16F, so what it writes carries the history's precision, not the output's. Per column, the
// output averaged over rows and the last frames is compared with the RGBA16F history's (in sRGB
// levels). A history rounded to nearest stops moving once alpha * |current - history| is under
// half a level (alpha = 1/16: eight levels) and keeps the level it stopped at: its column means
// then step with the history's levels against the smooth gradient.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <glm/gtc/quaternion.hpp>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "gpu_image.h"
#include "steadyxr/core/filter.h"
#include "validated_context_test.h"

using namespace steadyxr::core;
using steadyxr::test::GpuImage;
using steadyxr::test::HostImage;
using steadyxr::test::ValidatedContextTest;

namespace {

constexpr uint32_t kW = 64, kH = 16;  // 16 levels over 64 px: a level every 4 px
constexpr float kTopLevel = 16.0f;    // sRGB 0..16/255: the dark end, where 8 bits band first
constexpr int kFrames = 64;
constexpr int kMeasured = 32;  // the last frames, averaged (the first ones are still converging)
constexpr float kTanHalfFov = 0.5f;
// Tremor: yaw uniformly within +-0.4 px per frame (seed 003's head tremor is sub-pixel at VR
// resolutions), so every frame reprojects the history by a fraction of a pixel.
constexpr float kTremorPx = 0.4f;

// The gradient in sRGB levels at a world azimuth (radians, right-positive): 0 at the left edge of
// the unrotated view, kTopLevel at the right.
float levelAt(float azimuth) {
  const float t = (std::tan(azimuth) + kTanHalfFov) / (2.0f * kTanHalfFov);
  return kTopLevel * std::clamp(t, 0.0f, 1.0f);
}
// The world azimuth seen at pixel column x under yaw (OpenXR: +y up, -z forward; a yaw turns the
// view left, so the world azimuth of a view ray is its view azimuth minus the yaw).
float azimuthAt(float x, float yaw) {
  return std::atan(-kTanHalfFov + 2.0f * kTanHalfFov * (x + 0.5f) / float(kW)) - yaw;
}

struct Bias {
  float maxAbs = 0;  // the largest |column mean difference| over the columns, in sRGB levels
  float rms = 0;     // over the columns
};

}  // namespace

class HistoryFormatTest : public ValidatedContextTest {
 protected:
  // Per column: the output's mean over rows, both eyes and the last kMeasured frames, minus the
  // gradient's level there, in sRGB levels. The same random sequence for every format.
  std::vector<double> columnMeans(HistoryFormat format) {
    Params params;  // the default method (steady)
    params.historyFormat = format;
    std::string err;
    auto filter = Filter::create(*ctx_, params, &err);
    EXPECT_TRUE(filter) << err;
    if (!filter) return {};
    std::array<std::unique_ptr<GpuImage>, 2> in, out;
    for (int e = 0; e < 2; ++e) {
      in[e] =
          std::make_unique<GpuImage>(*ctx_, VK_FORMAT_R8G8B8A8_SRGB, kW, kH, 1, VK_IMAGE_USAGE_SAMPLED_BIT);
      out[e] = std::make_unique<GpuImage>(*ctx_, VK_FORMAT_R16G16B16A16_SFLOAT, kW, kH, 1,
                                          VK_IMAGE_USAGE_STORAGE_BIT);
    }
    std::mt19937 rng(17);
    std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
    const float radPerPx = 2.0f * kTanHalfFov / float(kW);  // at the centre; small angles
    std::vector<double> sum(kW, 0.0);
    VkImageLayout outLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    float yaw = 0.0f;
    for (int f = 0; f < kFrames; ++f) {
      yaw = f == 0 ? 0.0f : kTremorPx * radPerPx * (2.0f * uniform(rng) - 1.0f);
      StereoFrame sf;
      StereoOutput so;
      sf.headSpeedDegPerSec = 1.0f;
      for (int e = 0; e < 2; ++e) {
        HostImage img(kW, kH);
        for (uint32_t y = 0; y < kH; ++y)
          for (uint32_t x = 0; x < kW; ++x) {
            const float level = std::floor(levelAt(azimuthAt(float(x), yaw)) + uniform(rng));  // app's dither
            const float c =
                float(steadyxr::test::srgbDecode(level / 255.0));  // GpuImage encodes back to exactly `level`
            img.at(x, y) = glm::vec4(c, c, c, 1.0f);
          }
        in[e]->upload(img, 0, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
        sf.views[e].color = in[e]->ref(0, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
        sf.views[e].pose.orientation = glm::angleAxis(yaw, glm::vec3(0, 1, 0));
        sf.views[e].fov = {-std::atan(kTanHalfFov), std::atan(kTanHalfFov), std::atan(kTanHalfFov),
                           -std::atan(kTanHalfFov)};
        so.views[e] = out[e]->ref(0, outLayout);
        so.views[e].finalLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
      }
      EXPECT_TRUE(filter->submit(sf, so, &err)) << err;
      filter->waitIdle();
      outLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
      if (f < kFrames - kMeasured) continue;
      // The error against this frame's gradient, so the tremor itself does not count.
      for (int e = 0; e < 2; ++e) {
        const HostImage got = out[e]->download(0, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
        for (uint32_t y = 0; y < kH; ++y)
          for (uint32_t x = 0; x < kW; ++x)
            sum[x] += 255.0f * float(steadyxr::test::srgbEncode(got.at(x, y).g)) -
                      levelAt(azimuthAt(float(x), yaw));
      }
    }
    for (double& m : sum) m /= double(2 * kH * kMeasured);
    return sum;
  }

  // The 8-bit history's column means against the RGBA16F history's: what the format adds. (The
  // RGBA16F output itself is off the gradient by up to a third of a level here, as `none` is:
  // lavapipe's sRGB decode of the input is approximate in the dark. That cancels.)
  Bias biasAgainstRgba16f(HistoryFormat format) {
    const std::vector<double> half = columnMeans(HistoryFormat::Rgba16f);
    const std::vector<double> eight = columnMeans(format);
    Bias b;
    if (half.size() != kW || eight.size() != kW) return {1e9f, 1e9f};
    // The outermost columns clamp their 3x3 at the edge: left out.
    for (uint32_t x = 1; x + 1 < kW; ++x) {
      const float d = float(eight[x] - half[x]);
      b.maxAbs = std::max(b.maxAbs, std::abs(d));
      b.rms += d * d;
    }
    b.rms = std::sqrt(b.rms / float(kW - 2));
    return b;
  }
};

// A tenth of a level: a stalled history leaves a sawtooth of a fifth of a level and more here, and
// the averaged dither noise of 2 x 16 x 32 samples per column stays well under it (figures printed).
constexpr float kMaxColumnBias = 0.1f;

TEST_F(HistoryFormatTest, DitheredEightBitHistoryKeepsADarkGradientWithoutBanding) {
  const Bias b = biasAgainstRgba16f(HistoryFormat::Rgba8Dithered);
  std::printf("column mean against rgba16f (sRGB levels): 8-bit dithered max %.3f rms %.3f\n", b.maxAbs,
              b.rms);
  EXPECT_LT(b.maxAbs, kMaxColumnBias);
}

// The measurement sees the stall: an 8-bit history rounded to nearest bands.
TEST_F(HistoryFormatTest, NearestRoundedEightBitHistoryBands) {
  const Bias b = biasAgainstRgba16f(HistoryFormat::Rgba8Nearest);
  std::printf("column mean against rgba16f (sRGB levels): 8-bit nearest max %.3f rms %.3f\n", b.maxAbs,
              b.rms);
  EXPECT_GT(b.maxAbs, kMaxColumnBias);
}

// Float inputs may hold values outside [0, 1], the stereo pass reads the history as it is, and
// Catmull-Rom sampling reads it through the sampler: all keep RGBA16F whatever is asked.
TEST(HistoryFormat, EightBitOnlyForEightBitInputsWithoutStereo) {
  Params p;
  p.historyFormat = HistoryFormat::Rgba8Dithered;
  EXPECT_EQ(historyFormat(p, VK_FORMAT_R8G8B8A8_SRGB), VK_FORMAT_R8G8B8A8_UNORM);
  EXPECT_EQ(historyFormat(p, VK_FORMAT_B8G8R8A8_UNORM), VK_FORMAT_R8G8B8A8_UNORM);
  EXPECT_EQ(historyFormat(p, VK_FORMAT_R16G16B16A16_SFLOAT), VK_FORMAT_R16G16B16A16_SFLOAT);
  p.stereo = true;
  EXPECT_EQ(historyFormat(p, VK_FORMAT_R8G8B8A8_SRGB), VK_FORMAT_R16G16B16A16_SFLOAT);
  p.stereo = false;
  p.historyFilter = HistoryFilter::CatmullRom;
  EXPECT_EQ(historyFormat(p, VK_FORMAT_R8G8B8A8_SRGB), VK_FORMAT_R16G16B16A16_SFLOAT);
  p.historyFilter = HistoryFilter::Bilinear;
  p.historyFormat = HistoryFormat::Rgba16f;
  EXPECT_EQ(historyFormat(p, VK_FORMAT_R8G8B8A8_SRGB), VK_FORMAT_R16G16B16A16_SFLOAT);
}
