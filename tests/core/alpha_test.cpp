// Alpha through the filter on real Vulkan (lavapipe) with VK_LAYER_KHRONOS_validation: every
// method outputs exactly the app's alpha at each pixel (carried through, never filtered: see
// common.glsl), and `none` is a bit-exact copy of all four channels.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <glm/gtc/packing.hpp>
#include <glm/gtc/quaternion.hpp>
#include <memory>
#include <string>

#include "gpu_image.h"
#include "steadyxr/core/filter.h"
#include "validated_context_test.h"

using namespace steadyxr;
using namespace steadyxr::core;
using test::GpuImage;
using test::HostImage;
using test::ValidatedContextTest;

namespace {

constexpr float kDeg = 3.14159265358979f / 180.0f;

bool isSrgb(VkFormat f) {
  return f == VK_FORMAT_R8G8B8A8_SRGB || f == VK_FORMAT_B8G8R8A8_SRGB;
}
bool isHalf(VkFormat f) {
  return f == VK_FORMAT_R16G16B16A16_SFLOAT;
}

// What one channel is stored as, independent of the shader: the 8-bit code (sRGB-encoded colour
// for SRGB formats; alpha is linear in every format, Vulkan spec "sRGB transfer functions") or the
// half-float bits. GpuImage decodes sRGB on download, so colour is encoded back here.
uint32_t storedCode(VkFormat f, float v, bool isAlpha) {
  if (isHalf(f)) return glm::packHalf1x16(v);
  if (isSrgb(f) && !isAlpha) v = float(steadyxr::test::srgbEncode(v));
  return static_cast<uint32_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f));
}

// Colour with edges (so every filter changes it) and an alpha that varies per pixel, per eye and
// per frame over the whole range, 0 and 1 included. Half-float inputs also get values outside
// [0, 1] in colour, which only `none` must keep.
HostImage scene(uint32_t w, uint32_t h, int eye, int frame, bool wideRange) {
  HostImage img(w, h);
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x) {
      const bool edge = ((x + static_cast<uint32_t>(frame)) / 3 + y / 5) % 2 != 0;
      glm::vec3 c = edge ? glm::vec3(0.9f, 0.8f, 0.1f) : glm::vec3(0.1f, 0.2f, 0.7f);
      c.g += 0.03f * float((x * 7 + y * 3) % 5);
      if (wideRange && (x + y) % 7 == 0) c = {-0.25f, 1.75f, 3.5f};
      const uint32_t a =
          (x * 37u + y * 11u + static_cast<uint32_t>(eye) * 101u + static_cast<uint32_t>(frame) * 53u) % 256u;
      img.at(x, y) = glm::vec4(c, float(a) / 255.0f);
    }
  return img;
}

struct FormatCase {
  VkFormat in, out;
  VkImageUsageFlags outUsage;
  bool outMutable;
};

}  // namespace

class AlphaTest : public ValidatedContextTest {
 protected:
  // Runs `frames` frames of `method` with a small head turn and returns the mismatch count of
  // alpha (or all four channels when `allChannels`) between every output and its input.
  int mismatches(const std::string& method, const FormatCase& fc, int frames, bool allChannels) {
    const uint32_t W = 22, H = 18;  // not a multiple of the 4x4 invocation block: partial blocks
    auto params = applyMethodName(method);
    EXPECT_TRUE(params) << method;
    if (!params) return -1;
    std::string err;
    auto filter = Filter::create(*ctx_, *params, &err);
    EXPECT_TRUE(filter) << err;
    if (!filter) return -1;
    std::array<std::unique_ptr<GpuImage>, 2> in, out;
    for (int e = 0; e < 2; ++e) {
      in[e] = std::make_unique<GpuImage>(*ctx_, fc.in, W, H, 1, VK_IMAGE_USAGE_SAMPLED_BIT);
      out[e] = std::make_unique<GpuImage>(*ctx_, fc.out, W, H, 1, fc.outUsage, fc.outMutable);
    }
    VkImageLayout outLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    int bad = 0;
    for (int f = 0; f < frames; ++f) {
      StereoFrame sf;
      StereoOutput so;
      sf.headSpeedDegPerSec = 2.0f;
      std::array<HostImage, 2> src;
      for (int e = 0; e < 2; ++e) {
        src[e] = scene(W, H, e, f, isHalf(fc.in));
        in[e]->upload(src[e], 0, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
        sf.views[e].color = in[e]->ref(0, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
        sf.views[e].pose.orientation = glm::angleAxis(0.3f * float(f) * kDeg, glm::vec3(0, 1, 0));
        sf.views[e].pose.position = glm::vec3(0.064f * float(e), 0.0f, 0.0f);
        so.views[e] = out[e]->ref(0, outLayout);
        so.views[e].finalLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
      }
      EXPECT_TRUE(filter->submit(sf, so, &err)) << method << ": " << err;
      filter->waitIdle();
      outLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
      for (int e = 0; e < 2; ++e) {
        const HostImage got = out[e]->download(0, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
        for (uint32_t i = 0; i < got.px.size(); ++i)
          for (int k = allChannels ? 0 : 3; k < 4; ++k) {
            // The input's stored code through the input format, then the output format.
            const float want = isHalf(fc.in) ? glm::unpackHalf1x16(storedCode(fc.in, src[e].px[i][k], k == 3))
                                             : float(storedCode(fc.in, src[e].px[i][k], k == 3)) / 255.0f;
            const bool srgbColour = isSrgb(fc.in) && k < 3;
            const float wantLinear = srgbColour ? float(steadyxr::test::srgbDecode(want)) : want;
            if (storedCode(fc.out, got.px[i][k], k == 3) != storedCode(fc.out, wantLinear, k == 3)) ++bad;
          }
      }
    }
    return bad;
  }
};

TEST_F(AlphaTest, EveryMethodOutputsTheInputAlphaExactly) {
  const FormatCase cases[] = {
      {VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_R8G8B8A8_UNORM, VK_IMAGE_USAGE_STORAGE_BIT, false},
      {VK_FORMAT_R8G8B8A8_SRGB, VK_FORMAT_B8G8R8A8_SRGB, 0, false},  // intermediate + swizzled copy
      {VK_FORMAT_R16G16B16A16_SFLOAT, VK_FORMAT_R16G16B16A16_SFLOAT, VK_IMAGE_USAGE_STORAGE_BIT, false},
  };
  for (const char* m : {"none", "fxaa", "taa", "hmtaa", "vtaa", "hybrid", "steady", "steady+stereo", "stereo",
                        "taa+stereo", "fxaa+stereo", "default"})
    for (const FormatCase& fc : cases)
      EXPECT_EQ(mismatches(m, fc, 3, false), 0) << m << " in " << fc.in << " out " << fc.out;
}

TEST_F(AlphaTest, NoneIsABitExactCopyOfAllFourChannels) {
  const FormatCase cases[] = {
      {VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_R8G8B8A8_UNORM, VK_IMAGE_USAGE_STORAGE_BIT, false},
      {VK_FORMAT_B8G8R8A8_UNORM, VK_FORMAT_B8G8R8A8_UNORM, 0, false},
      {VK_FORMAT_R8G8B8A8_SRGB, VK_FORMAT_R8G8B8A8_SRGB, VK_IMAGE_USAGE_STORAGE_BIT, true},  // UNORM view
      {VK_FORMAT_R16G16B16A16_SFLOAT, VK_FORMAT_R16G16B16A16_SFLOAT, VK_IMAGE_USAGE_STORAGE_BIT, false},
  };
  for (const FormatCase& fc : cases)
    EXPECT_EQ(mismatches("none", fc, 2, true), 0) << "in " << fc.in << " out " << fc.out;
}
