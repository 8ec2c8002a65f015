// The filter's contract with its caller on real Vulkan (lavapipe, validation on): the context,
// sub-rects, layers and output formats, reset, NaN/Inf inputs, borrowed handles, bad frames.
#include <gtest/gtest.h>

#include <cmath>
#include <glm/gtc/packing.hpp>
#include <glm/gtc/quaternion.hpp>
#include <random>
#include <string>
#include <vector>

#include "filter_test_rig.h"

using namespace steadyxr;
using namespace steadyxr::core;
using namespace steadyxr::test;

TEST_F(CoreTest, ContextPicksCpuDeviceAndHasTimestamps) {
  EXPECT_TRUE(ctx_->owned());
  uint32_t n = 0;
  vkEnumeratePhysicalDevices(ctx_->instance(), &n, nullptr);
  std::vector<VkPhysicalDevice> devices(n);
  vkEnumeratePhysicalDevices(ctx_->instance(), &n, devices.data());
  bool haveCpuDevice = false;
  for (VkPhysicalDevice d : devices) {
    VkPhysicalDeviceProperties props;
    vkGetPhysicalDeviceProperties(d, &props);
    haveCpuDevice = haveCpuDevice || props.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
  }
  // The suite also runs on GPU-only machines (README: measured on a real GPU).
  if (haveCpuDevice) {
    EXPECT_EQ(ctx_->properties().deviceType, VK_PHYSICAL_DEVICE_TYPE_CPU);
  }
  EXPECT_EQ(ctx_->isCpuDevice(), ctx_->properties().deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU);
  auto f = makeFilter("none");
  Rig rig(32, 16);
  Frame fr;
  fr.color = {pattern(32, 16, 1), pattern(32, 16, 2)};
  fr.views = {eye(0, 0), eye(0, 0)};
  rig.run(*f, fr);
  const auto t = f->lastTimings();
  ASSERT_TRUE(t);
  EXPECT_GT(t->totalMs, 0.0);
  EXPECT_GE(t->totalMs + 1e-9, t->temporalMs + t->stereoMs + t->otherMs - 1e-6);
}

// Round 49: the probe's time is its own span inside the first stage's (the bench prints it).
TEST_F(CoreTest, DefaultTimesItsProbeInsideTheFirstStage) {
  auto f = makeFilter("default");
  Rig rig(32, 16);
  const Frame fr{{pattern(32, 16, 5), pattern(32, 16, 6)}, {eye(0, 0), eye(0, 0)}};
  rig.run(*f, fr);
  rig.run(*f, fr);
  const auto t = f->lastTimings();
  ASSERT_TRUE(t);
  EXPECT_GT(t->probeMs, 0.0);
  EXPECT_LT(t->probeMs, t->temporalMs);  // the temporal passes follow it
  EXPECT_GE(t->totalMs + 1e-9, t->temporalMs + t->stereoMs + t->otherMs - 1e-6);
}

TEST_F(CoreTest, NoneCopiesSubRectsOfLayeredSrgbImages) {
  // Both eyes in one 2-layer SRGB image, each at a sub-rect; output the same, at another offset.
  const uint32_t W = 80, H = 60, w = 64, h = 48;
  GpuImage in(*gCtx, VK_FORMAT_R8G8B8A8_SRGB, W, H, 2, VK_IMAGE_USAGE_SAMPLED_BIT);
  GpuImage out(*gCtx, VK_FORMAT_R8G8B8A8_SRGB, W, H, 2, VK_IMAGE_USAGE_STORAGE_BIT, true);
  const HostImage marker(W, H, glm::vec4(0.2f, 0.0f, 1.0f, 1.0f));
  std::array<HostImage, 2> src = {pattern(W, H, 3), pattern(W, H, 4)};
  StereoFrame sf;
  StereoOutput so;
  for (uint32_t e = 0; e < 2; ++e) {
    in.upload(src[e], e, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    out.upload(marker, e, VK_IMAGE_LAYOUT_GENERAL);
    sf.views[e].color = in.ref(e, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, {{5, 7}, {w, h}});
    so.views[e] = out.ref(e, VK_IMAGE_LAYOUT_GENERAL, {{int32_t(3 + e), 9}, {w, h}});
    so.views[e].finalLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
  }
  auto f = makeFilter("none");
  std::string err;
  ASSERT_TRUE(f->submit(sf, so, &err)) << err;
  f->waitIdle();
  for (uint32_t e = 0; e < 2; ++e) {
    const HostImage got = out.download(e, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
    int bad = 0;
    for (uint32_t y = 0; y < H; ++y)
      for (uint32_t x = 0; x < W; ++x) {
        const bool inside = x >= 3 + e && x < 3 + e + w && y >= 9 && y < 9 + h;
        const glm::vec4 want = inside ? src[e].at(x - 3 - e + 5, y - 9 + 7) : marker.at(x, y);
        if (glm::any(
                glm::greaterThan(glm::abs(glm::vec3(got.at(x, y)) - glm::vec3(want)), glm::vec3(0.004f))))
          ++bad;
      }
    EXPECT_EQ(bad, 0) << "eye " << e;
  }
}

TEST_F(CoreTest, NoneWritesEveryOutputFormat) {
  struct Case {
    VkFormat fmt;
    VkImageUsageFlags usage;
    bool mut;
  };
  // Worst-case quantisation in linear light: half an 8-bit step, times the sRGB curve's slope
  // (at most 2.28, plus the decoder's own allowed error) for SRGB formats; half precision for RGBA16F.
  auto quant = [](VkFormat f) {
    if (f == VK_FORMAT_R16G16B16A16_SFLOAT) return 5e-4f;
    const bool srgb = f == VK_FORMAT_R8G8B8A8_SRGB || f == VK_FORMAT_B8G8R8A8_SRGB;
    return 0.5f / 255.0f * (srgb ? 2.6f : 1.0f);
  };
  const Case cases[] = {
      {VK_FORMAT_R8G8B8A8_UNORM, VK_IMAGE_USAGE_STORAGE_BIT, false},  // direct
      {VK_FORMAT_R8G8B8A8_SRGB, 0, false},                            // intermediate + copy
      {VK_FORMAT_B8G8R8A8_UNORM, 0, false},                           // swizzle + copy
      {VK_FORMAT_B8G8R8A8_SRGB, VK_IMAGE_USAGE_STORAGE_BIT, true},    // UNORM view, encode
      {VK_FORMAT_R16G16B16A16_SFLOAT, VK_IMAGE_USAGE_STORAGE_BIT, false},
  };
  for (const auto inFmt : {VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_B8G8R8A8_SRGB}) {
    for (const Case& c : cases) {
      Rig rig(24, 20, inFmt, c.fmt, c.usage, c.mut);
      auto f = makeFilter("none");
      Frame fr;
      fr.color = {pattern(24, 20, 5), pattern(24, 20, 6)};
      fr.views = {eye(0, 0), eye(0, 0)};
      auto out = rig.run(*f, fr);
      for (int e = 0; e < 2; ++e)
        EXPECT_LE(compare(out[e], fr.color[e]).maxAbs, quant(inFmt) + quant(c.fmt) + 1e-4f)
            << "in " << inFmt << " out " << c.fmt;
    }
  }
}

TEST_F(CoreTest, ResetClearsHistory) {
  auto f = makeFilter("taa");
  Rig rig(32, 32);
  const HostImage a = pattern(32, 32, 20), b = pattern(32, 32, 21, 0.2f);
  for (int i = 0; i < 3; ++i) rig.run(*f, Frame{{a, a}, {eye(0, 0), eye(0, 0)}});
  const auto blended = rig.run(*f, Frame{{b, b}, {eye(0, 0), eye(0, 0)}});
  EXPECT_GT(compare(blended[0], b).meanAbs, 0.01f);  // history is in use

  Frame fr{{b, b}, {eye(0, 0), eye(0, 0)}};
  fr.reset = true;  // frame flag
  EXPECT_LE(compare(rig.run(*f, fr)[0], b).maxAbs, 1e-3f);
  rig.run(*f, Frame{{a, a}, {eye(0, 0), eye(0, 0)}});
  f->reset();  // API call
  EXPECT_LE(compare(rig.run(*f, Frame{{b, b}, {eye(0, 0), eye(0, 0)}})[0], b).maxAbs, 1e-3f);
  rig.run(*f, Frame{{a, a}, {eye(0, 0), eye(0, 0)}});
  // pose jump beyond resetAngleDeg (30)
  EXPECT_LE(compare(rig.run(*f, Frame{{b, b}, {eye(40, 0), eye(40, 0)}})[0], b).maxAbs, 1e-3f);
  // method change resets
  rig.run(*f, Frame{{a, a}, {eye(40, 0), eye(40, 0)}});
  Params p = f->params();
  p.temporal = TemporalMethod::Vtaa;
  f->setParams(p);
  EXPECT_LE(compare(rig.run(*f, Frame{{b, b}, {eye(40, 0), eye(40, 0)}})[0], b).maxAbs, 1e-3f);
  // a rect larger than the history's images starts without it (a smaller one keeps it: an app's dynamic
  // resolution, dynamic_resolution_test.cpp)
  Rig large(48, 40);
  const HostImage c = pattern(48, 40, 22);
  EXPECT_LE(compare(large.run(*f, Frame{{c, c}, {eye(40, 0), eye(40, 0)}})[0], c).maxAbs, 1e-3f);
}

TEST_F(CoreTest, NanAndInfNeverReachTheHistory) {
  for (const char* m : {"taa", "hmtaa", "vtaa", "default"}) {
    auto f = makeFilter(m);
    Rig rig(32, 32);
    HostImage bad = pattern(32, 32, 30);
    bad.at(5, 5) = glm::vec4(NAN, 0.5f, 0.5f, 1.0f);
    bad.at(6, 5) = glm::vec4(INFINITY, -INFINITY, 0.5f, 1.0f);
    bad.at(20, 20) = glm::vec4(NAN);
    auto finite = [](const HostImage& img) {
      for (const auto& px : img.px)
        if (!std::isfinite(px.r) || !std::isfinite(px.g) || !std::isfinite(px.b)) return false;
      return true;
    };
    auto o1 = rig.run(*f, Frame{{bad, bad}, {eye(0, 0), eye(0, 0)}});
    Frame nanPose{{bad, bad}, {eye(0.5f, 0), eye(0.5f, 0)}};
    nanPose.views[0].pose.orientation.x = NAN;
    nanPose.views[1].pose.position.y = INFINITY;
    nanPose.headSpeed = NAN;
    auto o2 = rig.run(*f, nanPose);
    const HostImage good = pattern(32, 32, 31);
    auto o3 = rig.run(*f, Frame{{good, good}, {eye(1, 0), eye(1, 0)}});
    auto o4 = rig.run(*f, Frame{{good, good}, {eye(1.2f, 0), eye(1.2f, 0)}});
    for (int e = 0; e < 2; ++e) {
      EXPECT_TRUE(finite(o1[e]) && finite(o2[e]) && finite(o3[e]) && finite(o4[e])) << m;
    }
  }
}

TEST_F(CoreTest, BorrowedContextNeverDestroysTheAppsHandles) {
  BorrowedHandles h;
  h.instance = ctx_->instance();
  h.physicalDevice = ctx_->physicalDevice();
  h.device = ctx_->device();
  h.queueFamilyIndex = ctx_->queueFamilyIndex();
  std::string err;
  {
    auto borrowed = VulkanContext::borrow(h, &err);
    ASSERT_TRUE(borrowed) << err;
    EXPECT_FALSE(borrowed->owned());
    EXPECT_EQ(borrowed->device(), ctx_->device());
    auto f = Filter::create(*borrowed, *applyMethodName("default"), &err);
    ASSERT_TRUE(f) << err;
    Rig rig(16, 16);
    const HostImage img = pattern(16, 16, 40);
    rig.run(*f, Frame{{img, img}, {eye(0, 0), eye(0, 0)}});
  }
  // the device is still alive and usable after the borrowed context and its filter are gone
  auto f = makeFilter("none");
  Rig rig(16, 16);
  const HostImage img = pattern(16, 16, 41);
  EXPECT_LE(compare(rig.run(*f, Frame{{img, img}, {eye(0, 0), eye(0, 0)}})[0], img).maxAbs, 1e-3f);
  BorrowedHandles none;
  EXPECT_FALSE(VulkanContext::borrow(none, &err));
  EXPECT_FALSE(err.empty());
}

TEST_F(CoreTest, RejectsBadFramesWithoutCrashing) {
  auto f = makeFilter("default");
  GpuImage in(*gCtx, VK_FORMAT_R8G8B8A8_UNORM, 16, 16, 1, VK_IMAGE_USAGE_SAMPLED_BIT);
  GpuImage out(*gCtx, VK_FORMAT_R8G8B8A8_UNORM, 8, 8, 1, VK_IMAGE_USAGE_STORAGE_BIT);
  StereoFrame sf;
  StereoOutput so;
  sf.views[0].color = sf.views[1].color = in.ref(0, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
  so.views[0] = so.views[1] = out.ref(0, VK_IMAGE_LAYOUT_GENERAL);
  std::string err;
  EXPECT_FALSE(f->submit(sf, so, &err));  // size mismatch
  EXPECT_FALSE(err.empty());
  sf.viewCount = 3;
  EXPECT_FALSE(f->submit(sf, so, &err));
  sf.viewCount = 2;
  sf.views[0].color.rect = {{10, 10}, {16, 16}};
  EXPECT_FALSE(f->submit(sf, so, &err));  // rect outside the image
  EXPECT_FALSE(Filter::create(
      *gCtx,
      [] {
        Params p;
        p.wMin = -1;
        return p;
      }(),
      &err));
}
