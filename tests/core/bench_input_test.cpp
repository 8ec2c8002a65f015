// steadyxr-bench's eye images (layer/core/bench/bench_input.h): the renderer's pixel directions against
// the core's own projection, the upload in each input format, and what the picture gives the default's
// noise probe that a flat clear does not.
#include <gtest/gtest.h>

#include <cmath>
#include <glm/gtc/color_space.hpp>
#include <glm/gtc/quaternion.hpp>
#include <vector>

#include "bench_input.h"
#include "filter_test_rig.h"
#include "gpu_image.h"

using namespace steadyxr;
using namespace steadyxr::core;
using namespace steadyxr::test;

namespace {
const Fov kFov{-0.8f, 0.75f, 0.78f, -0.82f};  // the bench's, asymmetric as a headset's

HostImage toHost(VkExtent2D size, const std::vector<glm::vec4>& pixels) {
  HostImage img(size.width, size.height);
  img.px = pixels;
  return img;
}
}  // namespace

// Each pixel's world direction, carried back through the core's projection and view matrices
// (view_math.h: Vulkan's NDC, y down), lands on that pixel's centre, at an orientation off every axis.
TEST(BenchInput, PixelDirectionProjectsBackToItsPixel) {
  const VkExtent2D size{64, 48};
  Pose pose;
  pose.orientation = glm::angleAxis(0.3f, glm::vec3(0, 1, 0)) * glm::angleAxis(-0.2f, glm::vec3(1, 0, 0));
  const glm::mat4 viewProjection = projectionFromFov(kFov, 0.05f, INFINITY) * viewFromPose(pose);
  for (const glm::vec2 p : {glm::vec2(0, 0), glm::vec2(63, 0), glm::vec2(10, 30), glm::vec2(63, 47)}) {
    const glm::vec3 d = steadyxr::bench::pixelDirection(size, kFov, pose.orientation, p.x, p.y);
    const glm::vec4 clip = viewProjection * glm::vec4(d, 0.0f);  // a direction: the eye's offset drops out
    ASSERT_GT(clip.w, 0.0f) << "behind the eye";
    const glm::vec2 ndc(clip.x / clip.w, clip.y / clip.w);
    const glm::vec2 pixel = (ndc + 1.0f) * 0.5f * glm::vec2(size.width, size.height) - 0.5f;
    EXPECT_NEAR(pixel.x, p.x, 1e-3f) << p.x << ", " << p.y;
    EXPECT_NEAR(pixel.y, p.y, 1e-3f) << p.x << ", " << p.y;
  }
}

// uploadImage stores the picture as each input format holds it: sRGB codes (glm's encoder, not the bench's),
// UNORM codes of the values themselves, half floats. GpuImage reads them back (decoding sRGB from the
// standard).
TEST_F(CoreTest, BenchInputUploadStoresThePictureInEachFormat) {
  const VkExtent2D size{40, 24};
  const auto pixels = steadyxr::bench::renderZonePlate(size, kFov, glm::quat(1, 0, 0, 0));
  for (const VkFormat format :
       {VK_FORMAT_R8G8B8A8_SRGB, VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_R16G16B16A16_SFLOAT}) {
    GpuImage image(
        *gCtx, format, size.width, size.height, 1,
        VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
    std::string err;
    ASSERT_TRUE(steadyxr::bench::uploadImage(*gCtx, image.image(), format, size, pixels, &err)) << err;
    const HostImage back = image.download(0, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    float worst = 0.0f;
    for (size_t i = 0; i < pixels.size(); ++i)
      for (int c = 0; c < 4; ++c) {
        const float want = pixels[i][c], got = back.px[i][c];
        float error = std::abs(got - want);  // in the stored units: codes, or half-float steps
        if (format == VK_FORMAT_R8G8B8A8_SRGB && c < 3)
          error = 255.0f * std::abs(float(srgbEncode(got)) - glm::convertLinearToSRGB(glm::vec3(want)).x);
        else if (format != VK_FORMAT_R16G16B16A16_SFLOAT)
          error *= 255.0f;
        else
          error /= std::exp2(std::floor(std::log2(std::max(want, 1e-4f))) - 10.0f);  // half's ulp at want
        worst = std::max(worst, error);
      }
    // Half a step of rounding; glm's encoder takes 0.41666 for 1 / 2.4, a hundredth of a code off at most.
    EXPECT_LE(worst, format == VK_FORMAT_R16G16B16A16_SFLOAT ? 0.5f : 0.51f) << "format " << format;
  }
}

// Why the bench renders a picture: in the default's frames at the bench's tremor the probe finds the
// picture's detail, and the noise estimate exists; in a flat clear's it finds none (every sample in the
// histogram's bin 0), so the estimate never exists and the passes never widen a box or trade a blur.
TEST_F(CoreTest, BenchInputGivesTheNoiseProbeDetailAFlatClearDoesNot) {
  const VkExtent2D size{96, 80};
  for (const bool flat : {false, true}) {
    auto filter = makeFilter("default");
    ASSERT_TRUE(filter);
    Rig rig(size.width, size.height, VK_FORMAT_R8G8B8A8_SRGB);
    for (int i = 0; i < 4; ++i) {
      Frame fr;
      RefView view;
      view.fov = kFov;
      view.pose.orientation = glm::angleAxis(0.001f * float(i), glm::vec3(0, 1, 0));
      fr.views = {view, view};
      const HostImage img =
          flat ? HostImage(size.width, size.height, glm::vec4(0.2f, 0.4f, 0.6f, 1.0f))
               : toHost(size, steadyxr::bench::renderZonePlate(size, kFov, view.pose.orientation));
      fr.color = {img, img};
      fr.headSpeed = 4.0f;
      rig.run(*filter, fr);
    }
    filter->waitIdle();
    const std::optional<float> noise = filter->estimatedNoiseVariance();
    if (flat) {
      EXPECT_FALSE(noise.has_value()) << "a flat clear's probe found detail";
    } else {
      ASSERT_TRUE(noise.has_value()) << "the picture's probe found no detail";
      EXPECT_GT(*noise, 0.0f);
    }
  }
}
