// What the filter suites share: the CoreTest fixture (one validated context), a Rig that runs
// frames through a Filter on GPU images, test patterns, eye poses and image comparisons.
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <memory>
#include <string>

#include <glm/vec2.hpp>

#include "gpu_image.h"
#include "reference.h"
#include "steadyxr/core/filter.h"
#include "steadyxr/core/view_math.h"
#include "validated_context_test.h"

namespace steadyxr::test {

constexpr float kDeg = 3.14159265358979f / 180.0f;

// The running suite's context (CoreTest::SetUpTestSuite).
inline core::VulkanContext* gCtx = nullptr;

class CoreTest : public ValidatedContextTest {
 protected:
  static void SetUpTestSuite() {
    ValidatedContextTest::SetUpTestSuite();
    gCtx = ctx_.get();
  }
  static void TearDownTestSuite() {
    gCtx = nullptr;
    ValidatedContextTest::TearDownTestSuite();
  }
};

struct Frame {
  std::array<HostImage, 2> color;  // smaller than the Rig: a rect at its images' top-left corner
  std::array<RefView, 2> views;
  std::array<HostImage, 2> depth{};  // empty = none
  float headSpeed = 0.0f;
  bool reset = false;
  std::array<glm::vec2, 2> jitter{};  // ViewFrame::jitterPx
};

// Per-eye input/output images of one size; runs frames through a Filter and reads outputs back.
class Rig {
 public:
  Rig(uint32_t w, uint32_t h, VkFormat inFmt = VK_FORMAT_R16G16B16A16_SFLOAT,
      VkFormat outFmt = VK_FORMAT_R16G16B16A16_SFLOAT,
      VkImageUsageFlags outUsage = VK_IMAGE_USAGE_STORAGE_BIT, bool outMutable = false)
      : Rig(*gCtx, w, h, inFmt, outFmt, outUsage, outMutable) {}
  // On another context than the suite's (its filters' pipelines are that context's own).
  Rig(core::VulkanContext& ctx, uint32_t w, uint32_t h, VkFormat inFmt = VK_FORMAT_R16G16B16A16_SFLOAT,
      VkFormat outFmt = VK_FORMAT_R16G16B16A16_SFLOAT,
      VkImageUsageFlags outUsage = VK_IMAGE_USAGE_STORAGE_BIT, bool outMutable = false);
  // submitted: where to put submit()'s result; without it the submit must succeed.
  std::array<HostImage, 2> run(core::Filter& f, const Frame& fr, uint32_t viewCount = 2,
                               bool* submitted = nullptr);

 private:
  uint32_t w_, h_;
  std::array<std::unique_ptr<GpuImage>, 2> in_, out_, depth_;
  VkImageLayout outLayout_ = VK_IMAGE_LAYOUT_UNDEFINED;
};

std::unique_ptr<core::Filter> makeFilter(const std::string& method, core::Params p = {});

// A smooth pattern with edges and fine detail, plus optional per-pixel noise.
HostImage pattern(uint32_t w, uint32_t h, uint32_t seed, float noise = 0.0f);

HostImage toHalf(const HostImage& img);  // what an RGBA16F history holds

struct Diff {
  float maxAbs = 0.0f;
  float meanAbs = 0.0f;
};
Diff compare(const HostImage& a, const HostImage& b);  // over RGB
double rmse(const HostImage& a, const HostImage& b);   // over RGB

// Steady's box alone: round 15's noise estimate would widen it by the render's noise, and round 16's gain
// would undo a fade before the box sees it (each checked in its own suite).
core::Params steadyBoxAlone();

RefView eye(float yawDeg, float pitchDeg, glm::vec3 pos = glm::vec3(0));

}  // namespace steadyxr::test
