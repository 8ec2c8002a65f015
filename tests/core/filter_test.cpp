// The filter on real Vulkan (lavapipe) with VK_LAYER_KHRONOS_validation: every pass against the
// CPU reference, and the properties the issue asks for. Zero validation messages per test.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <glm/gtc/packing.hpp>
#include <glm/gtc/quaternion.hpp>
#include <random>
#include <thread>

#include "gpu_image.h"
#include "reference.h"
#include "steadyxr/core/filter.h"
#include "steadyxr/core/view_math.h"
#include "validated_context_test.h"

using namespace steadyxr;
using namespace steadyxr::core;
using test::GpuImage;
using test::HostImage;
using test::RefView;

namespace {

constexpr float kDeg = 3.14159265358979f / 180.0f;

VulkanContext* gCtx = nullptr;

struct Frame {
  std::array<HostImage, 2> color;
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
      : w_(w), h_(h) {
    for (int e = 0; e < 2; ++e) {
      in_[e] = std::make_unique<GpuImage>(*gCtx, inFmt, w, h, 1, VK_IMAGE_USAGE_SAMPLED_BIT);
      out_[e] = std::make_unique<GpuImage>(*gCtx, outFmt, w, h, 1, outUsage, outMutable);
      depth_[e] =
          std::make_unique<GpuImage>(*gCtx, VK_FORMAT_D32_SFLOAT, w, h, 1, VK_IMAGE_USAGE_SAMPLED_BIT);
    }
  }
  // submitted: where to put submit()'s result; without it the submit must succeed.
  std::array<HostImage, 2> run(Filter& f, const Frame& fr, uint32_t viewCount = 2,
                               bool* submitted = nullptr) {
    StereoFrame sf;
    StereoOutput so;
    sf.viewCount = viewCount;
    sf.headSpeedDegPerSec = fr.headSpeed;
    sf.reset = fr.reset;
    for (uint32_t e = 0; e < viewCount; ++e) {
      in_[e]->upload(fr.color[e], 0, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
      sf.views[e].color = in_[e]->ref(0, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
      sf.views[e].pose = fr.views[e].pose;
      sf.views[e].fov = fr.views[e].fov;
      sf.views[e].jitterPx = fr.jitter[e];
      if (!fr.depth[e].px.empty()) {
        depth_[e]->upload(fr.depth[e], 0, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
        DepthRef d;
        d.image = depth_[e]->ref(0, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
        d.nearZ = 0.1f;
        d.farZ = 100.0f;
        sf.views[e].depth = d;
      }
      so.views[e] = out_[e]->ref(0, outLayout_);
      so.views[e].finalLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    }
    std::string err;
    const bool ok = f.submit(sf, so, &err);
    if (submitted)
      *submitted = ok;
    else
      EXPECT_TRUE(ok) << err;
    f.waitIdle();
    outLayout_ = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    std::array<HostImage, 2> result;
    for (uint32_t e = 0; e < viewCount; ++e)
      result[e] = out_[e]->download(0, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
    return result;
  }

 private:
  uint32_t w_, h_;
  std::array<std::unique_ptr<GpuImage>, 2> in_, out_, depth_;
  VkImageLayout outLayout_ = VK_IMAGE_LAYOUT_UNDEFINED;
};

std::unique_ptr<Filter> makeFilter(const std::string& method, Params p = {}) {
  auto applied = applyMethodName(method, p);
  EXPECT_TRUE(applied) << method;
  std::string err;
  auto f = Filter::create(*gCtx, *applied, &err);
  EXPECT_TRUE(f) << err;
  return f;
}

// A smooth pattern with edges and fine detail, plus optional per-pixel noise.
HostImage pattern(uint32_t w, uint32_t h, uint32_t seed, float noise = 0.0f) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  HostImage img(w, h);
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x) {
      const float fx = float(x) / float(w), fy = float(y) / float(h);
      glm::vec3 c(0.5f + 0.4f * std::sin(fx * 9.0f + fy * 3.0f), 0.5f + 0.4f * std::cos(fy * 7.0f),
                  ((x / 8 + y / 8) % 2) ? 0.8f : 0.15f);
      if ((x - w / 2) * (x - w / 2) + (y - h / 3) * (y - h / 3) < w * w / 25) c = {0.95f, 0.9f, 0.1f};
      c += noise * glm::vec3(u(rng), u(rng), u(rng));
      img.at(x, y) = glm::vec4(glm::clamp(c, 0.0f, 1.0f), 1.0f);
    }
  return img;
}

HostImage toHalf(const HostImage& img) {  // what an RGBA16F history holds
  HostImage out = img;
  for (auto& p : out.px)
    for (int k = 0; k < 4; ++k) p[k] = glm::unpackHalf1x16(glm::packHalf1x16(p[k]));
  return out;
}

struct Diff {
  float maxAbs = 0.0f;
  float meanAbs = 0.0f;
};
Diff compare(const HostImage& a, const HostImage& b) {
  Diff d;
  double sum = 0.0;
  for (size_t i = 0; i < a.px.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      const float v = std::abs(a.px[i][k] - b.px[i][k]);
      d.maxAbs = std::max(d.maxAbs, std::isfinite(v) ? v : 1e9f);
      sum += v;
    }
  d.meanAbs = float(sum / (3.0 * double(a.px.size())));
  return d;
}

RefView eye(float yawDeg, float pitchDeg, glm::vec3 pos = glm::vec3(0)) {
  RefView v;
  v.pose.orientation =
      glm::angleAxis(yawDeg * kDeg, glm::vec3(0, 1, 0)) * glm::angleAxis(pitchDeg * kDeg, glm::vec3(1, 0, 0));
  v.pose.position = pos;
  v.fov = {-0.75f, 0.70f, 0.72f, -0.80f};  // asymmetric, as headsets report
  return v;
}

}  // namespace

class CoreTest : public test::ValidatedContextTest {
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

class TemporalReference : public CoreTest, public ::testing::WithParamInterface<std::string> {};

TEST_P(TemporalReference, MatchesCpuReference) {
  const std::string method = GetParam();
  const uint32_t W = 64, H = 64;
  Params p = *applyMethodName(method);
  if (method == "hmtaa2") {
    p = *applyMethodName("hmtaa");
    p.sampleCount = 2;
  }
  if (method == "hybrid-catmull" || method == "taa-catmull") {
    p = *applyMethodName(method.substr(0, method.find('-')));
    p.historyFilter = HistoryFilter::CatmullRom;
  }
  const bool withDepth = method == "taa-depth";
  if (withDepth) p = *applyMethodName("taa");
  std::string err;
  auto f = Filter::create(*gCtx, p, &err);
  ASSERT_TRUE(f) << err;
  Rig rig(W, H);
  Frame f1, f2;
  f1.color = {pattern(W, H, 7), pattern(W, H, 8)};
  f1.views = {eye(0.0f, 0.0f), eye(0.0f, 0.0f, {0.064f, 0, 0})};
  f2.color = {pattern(W, H, 9, 0.05f), pattern(W, H, 10, 0.05f)};
  f2.views = {eye(1.3f, -0.7f, {0.01f, 0.0f, 0.02f}), eye(1.3f, -0.7f, {0.074f, 0.0f, 0.02f})};
  f2.headSpeed = 6.0f;
  if (withDepth) {
    for (auto* fr : {&f1, &f2})
      for (int e = 0; e < 2; ++e) {
        fr->depth[e] = HostImage(W, H);
        for (uint32_t y = 0; y < H; ++y)
          for (uint32_t x = 0; x < W; ++x) {
            const float z = x < W / 2 ? 0.5f : 3.0f;  // metres: a near half and a far half
            fr->depth[e].at(x, y).r = (1.0f / z - 1.0f / 0.1f) / (1.0f / 100.0f - 1.0f / 0.1f);
          }
      }
  }
  const auto out1 = rig.run(*f, f1);
  for (int e = 0; e < 2; ++e) EXPECT_LE(compare(out1[e], f1.color[e]).maxAbs, 1e-3f) << "first frame = input";
  const auto out2 = rig.run(*f, f2);
  for (int e = 0; e < 2; ++e) {
    const auto method_ = p.temporal;
    const HostImage want =
        test::temporalRef(method_, p, toHalf(f2.color[e]), toHalf(f1.color[e]), true, f1.views[e],
                          f2.views[e], f2.headSpeed, withDepth ? &f2.depth[e] : nullptr, 0.1f, 100.0f);
    const Diff d = compare(out2[e], want);
    // Tolerance: GPU bilinear weights have 8 sub-texel bits (<= 1/256 of a neighbour difference),
    // RGBA16F storage (~1e-3). Few pixels sit exactly on a clip/fallback decision boundary.
    EXPECT_LE(d.meanAbs, 2e-3f) << method << " eye " << e;
    EXPECT_LE(d.maxAbs, 0.05f) << method << " eye " << e;
    // The filter did something: the output is not just the current frame.
    EXPECT_GT(compare(out2[e], f2.color[e]).meanAbs, 5e-3f) << method;
  }
}

INSTANTIATE_TEST_SUITE_P(Passes, TemporalReference,
                         ::testing::Values("taa", "hmtaa", "hmtaa2", "vtaa", "hybrid", "taa-depth",
                                           "hybrid-catmull", "taa-catmull"),
                         [](const auto& pinfo) {
                           std::string s = pinfo.param;
                           for (auto& c : s)
                             if (c == '-') c = '_';
                           return s;
                         });

// The steady method against its CPU reference, chained over four frames: the sample count
// builds up in the history's alpha, a patch that moves makes clips lower it, the head rotates and
// translates by sub-pixel amounts, and the frames carry noise.
class SteadyReference : public CoreTest, public ::testing::WithParamInterface<std::string> {};

TEST_P(SteadyReference, MatchesCpuReference) {
  const std::string variant = GetParam();
  const uint32_t W = 64, H = 64;
  Params p = *applyMethodName("steady");
  if (variant == "catmull") p.historyFilter = HistoryFilter::CatmullRom;
  if (variant == "interpolated") p.steadyInterpolated = true;
  if (variant == "rejectnoblur") {
    p.steadyClipRejects = true;
    p.steadyBlurBudgetPx2 = 0.0f;
  }
  if (variant == "constant") p.steadyConfidence = false;
  if (variant == "wideclip") {  // steady's clip box is its own, not taa's
    p.steadyClipGamma = 2.0f;
    p.taaClipGamma = 0.5f;
  }
  const bool withDepth = variant == "depth";
  auto f = makeFilter("steady", p);
  ASSERT_TRUE(f);
  Rig rig(W, H);
  std::array<HostImage, 2> hist;
  std::array<RefView, 2> prev;
  for (int k = 0; k < 4; ++k) {
    Frame fr;
    fr.color = {pattern(W, H, 20 + k, 0.05f), pattern(W, H, 30 + k, 0.05f)};
    for (auto& img : fr.color)  // a patch moving 3 px a frame over the static pattern
      for (uint32_t y = 40; y < 50; ++y)
        for (uint32_t x = 8u + 3u * uint32_t(k); x < 18u + 3u * uint32_t(k); ++x)
          img.at(x, y) = glm::vec4(1.0f, 0.2f, 0.6f, 1.0f);
    const float fk = float(k);
    fr.views = {eye(0.35f * fk, -0.2f * fk, {0.004f * fk, 0, 0.002f * fk}),
                eye(0.35f * fk, -0.2f * fk, {0.064f + 0.004f * fk, 0, 0.002f * fk})};
    for (int e = 0; e < 2 && withDepth; ++e) {
      fr.depth[e] = HostImage(W, H);
      for (uint32_t y = 0; y < H; ++y)
        for (uint32_t x = 0; x < W; ++x) {
          const float z = x < W / 2 ? 0.5f : 3.0f;  // metres: a near half and a far half
          fr.depth[e].at(x, y).r = (1.0f / z - 1.0f / 0.1f) / (1.0f / 100.0f - 1.0f / 0.1f);
        }
    }
    const auto out = rig.run(*f, fr);
    for (int e = 0; e < 2; ++e) {
      const HostImage want =
          toHalf(test::steadyRef(p, toHalf(fr.color[e]), hist[e], k > 0, prev[e], fr.views[e],
                                 withDepth ? &fr.depth[e] : nullptr, 0.1f, 100.0f));
      const Diff d = compare(out[e], want);
      // Tolerance as in TemporalReference (8 sub-texel bits of GPU bilinear weights, half
      // precision), over a chain of frames; few pixels sit on a clip decision boundary.
      EXPECT_LE(d.meanAbs, 2e-3f) << variant << " frame " << k << " eye " << e;
      EXPECT_LE(d.maxAbs, 0.05f) << variant << " frame " << k << " eye " << e;
      if (k > 0) {
        EXPECT_GT(compare(out[e], fr.color[e]).meanAbs, 5e-3f) << variant << ": the history is used";
      }
      hist[e] = want;
      prev[e] = fr.views[e];
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Variants, SteadyReference,
                         ::testing::Values("default", "catmull", "interpolated", "rejectnoblur", "constant",
                                           "depth", "wideclip"));

namespace {

// A static head and independent Gaussian noise (sigma 0.1 around grey) on every one of 64
// frames: the left output's mean squared error against grey after each frame.
std::vector<double> noiseMsePerFrame(Filter& f, uint32_t W, uint32_t H) {
  Rig rig(W, H);
  std::mt19937 rng(42);
  std::normal_distribution<float> g(0.0f, 0.1f);
  std::vector<double> mse;
  for (int n = 1; n <= 64; ++n) {
    HostImage img(W, H);
    for (auto& px : img.px) px = glm::vec4(0.5f + g(rng), 0.5f + g(rng), 0.5f + g(rng), 1.0f);
    const auto out = rig.run(f, Frame{{img, img}, {eye(0, 0), eye(0, 0)}}, 1);
    double s = 0;
    for (const auto& px : out[0].px)
      for (int k = 0; k < 3; ++k) s += (px[k] - 0.5) * (px[k] - 0.5);
    mse.push_back(s / (3.0 * W * H));
  }
  return mse;
}

}  // namespace

// Confidence-weighted accumulation: with a static head and independent noise on every frame, the
// weight 1/(n+1) averages N frames equally (noise sigma^2 / N) until the floor, where an
// exponential history of weight a keeps a / (2 - a) of it (1/31 at a = 1/16).
TEST_F(CoreTest, SteadyNoiseFallsLikeOneOverNToItsFloor) {
  const uint32_t W = 48, H = 48;
  Params p;
  // The accumulation alone: the footprint filter lowers white noise by itself, and the clip pulls
  // unlucky pixels towards their neighbours' mean (both measured below 1/N).
  p.steadyFootprint = 0.0f;
  p.steadyClipGamma = 1e3f;
  auto f = makeFilter("steady", p);
  ASSERT_TRUE(f);
  const std::vector<double> mse = noiseMsePerFrame(*f, W, H);
  const double sigma2 = 0.01;
  for (int n : {2, 4, 8, 16}) {
    const double ratio = mse[size_t(n - 1)] / (sigma2 / n);
    EXPECT_LT(ratio, 1.15) << "N = " << n << " mse " << mse[size_t(n - 1)];
    EXPECT_GT(ratio, 0.85) << "N = " << n << " mse " << mse[size_t(n - 1)];
  }
  const double a = Params{}.steadyAlphaFloor;
  const double floorRatio = mse[63] / (sigma2 * a / (2.0 - a));
  EXPECT_LT(floorRatio, 1.25) << "mse at N = 64: " << mse[63];
  EXPECT_GT(floorRatio, 0.8) << "mse at N = 64: " << mse[63] << " (1/N without the floor: 0.48)";
}

namespace {
// Pixels of `a` farther than `tolerance` from `b` in any channel.
int pixelsOff(const HostImage& a, const HostImage& b, float tolerance) {
  int n = 0;
  for (size_t i = 0; i < a.px.size(); ++i)
    n += glm::any(glm::greaterThan(glm::abs(glm::vec3(a.px[i]) - glm::vec3(b.px[i])), glm::vec3(tolerance)));
  return n;
}

float rmse(const HostImage& a, const HostImage& b) {
  double sum = 0.0;
  for (size_t i = 0; i < a.px.size(); ++i) {
    const glm::vec3 d = glm::vec3(a.px[i]) - glm::vec3(b.px[i]);
    sum += glm::dot(d, d);
  }
  return float(std::sqrt(sum / (3.0 * double(a.px.size()))));
}

// A straight step edge through the image centre at `slopeDeg` from horizontal (dark below-left,
// bright above-right), sampled at pixel centres (one sample per pixel, as a rasteriser without
// MSAA draws it) or as the 16x16 box average of each pixel (the ground truth).
HostImage steppedEdge(uint32_t w, uint32_t h, double slopeDeg, int samplesPerAxis) {
  const glm::dvec2 centre(w / 2.0 + 0.31, h / 2.0 + 0.17);  // off the pixel grid's symmetry
  const glm::dvec2 normal(-std::sin(slopeDeg * kDeg), std::cos(slopeDeg * kDeg));
  const glm::vec3 dark(0.05f, 0.08f, 0.1f), bright(0.9f, 0.7f, 0.5f);
  HostImage img(w, h);
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x) {
      int inside = 0;
      for (int j = 0; j < samplesPerAxis; ++j)
        for (int i = 0; i < samplesPerAxis; ++i) {
          const glm::dvec2 q(x + (i + 0.5) / samplesPerAxis, y + (j + 0.5) / samplesPerAxis);
          inside += glm::dot(q - centre, normal) < 0.0;  // image y grows downwards
        }
      const float f = float(inside) / float(samplesPerAxis * samplesPerAxis);
      img.at(x, y) = glm::vec4(glm::mix(dark, bright, f), 1.0f);
    }
  return img;
}
}  // namespace

TEST_F(CoreTest, FxaaMatchesCpuReference) {
  const uint32_t W = 64, H = 64;
  HostImage img(W, H);
  for (uint32_t y = 0; y < H; ++y)
    for (uint32_t x = 0; x < W; ++x) {
      // hard-edged shapes: a tilted edge, a circle, thin lines
      const bool a = float(y) > 0.35f * float(x) + 10.0f;
      const bool b = (x - 40) * (x - 40) + (y - 20) * (y - 20) < 120;
      const bool c = (x + 2 * y) % 11 == 0;
      // A little per-pixel texture: without it the repeated exact values make FXAA's comparisons
      // exact ties (e.g. edgeHorz == edgeVert beside the thin lines), which device and CPU
      // arithmetic may break either way.
      const float t = 0.03f * float((x * 7919u + y * 104729u) % 61u) / 60.0f;
      img.at(x, y) =
          glm::vec4((a ? 0.9f : 0.1f) - t, (b ? 0.8f : 0.2f) + t, (c ? 1.0f : 0.0f) + 0.5f * t, 1.0f);
    }
  auto f = makeFilter("fxaa");
  Rig rig(W, H);
  Frame fr;
  fr.color = {img, img};
  fr.views = {eye(0, 0), eye(0, 0)};
  const auto out = rig.run(*f, fr);
  const HostImage want = test::fxaaRef(toHalf(img));
  // Pixel by pixel: within the half-float output and the sampler's 8-bit bilinear weights
  // (1/256 of a step of at most 1), everywhere but a handful of pixels where a comparison of
  // equal float values (a luma tie) may go either way on the device.
  const int changed = pixelsOff(want, toHalf(img), 0.01f);
  const int off = pixelsOff(out[0], want, 0.01f);
  std::printf("fxaa vs the CPU reference: %d of %d pixels off by more than 0.01 (%d pixels changed)\n", off,
              int(W * H), changed);
  EXPECT_GT(changed, 300);  // the reference itself smoothed the edges
  EXPECT_LE(off, 4);
  EXPECT_LE(compare(out[0], want).meanAbs, 5e-4f);

  // A long, nearly horizontal edge (38 px steps): the search runs to its last, unsampled step.
  const HostImage longEdge = steppedEdge(W, H, 1.5, 1);
  fr.color = {longEdge, longEdge};
  const auto outLong = rig.run(*f, fr);
  const HostImage wantLong = test::fxaaRef(toHalf(longEdge));
  EXPECT_GT(pixelsOff(wantLong, toHalf(longEdge), 0.01f), 60);
  EXPECT_LE(pixelsOff(outLong[0], wantLong, 0.01f), 4);
  EXPECT_LE(compare(outLong[0], wantLong).meanAbs, 5e-4f);
}

TEST_F(CoreTest, FxaaLowersTheErrorOfASteppedEdgeAtEverySlope) {
  // FXAA against a supersampled edge: it must move every edge's pixels towards their coverage,
  // whatever the edge's direction (blending along the edge instead of across leaves the error).
  const uint32_t W = 64, H = 64;
  auto f = makeFilter("fxaa");
  Rig rig(W, H);
  for (double slope : {5.0, 20.0, 45.0, 70.0, 88.0}) {
    const HostImage aliased = steppedEdge(W, H, slope, 1), truth = steppedEdge(W, H, slope, 16);
    Frame fr;
    fr.color = {aliased, aliased};
    fr.views = {eye(0, 0), eye(0, 0)};
    const auto out = rig.run(*f, fr);
    const float before = rmse(toHalf(aliased), truth), after = rmse(out[0], truth);
    const float cpu = rmse(test::fxaaRef(toHalf(aliased)), truth);
    std::printf(
        "step edge at %4.1f deg: RMSE vs 16x16 supersampled %.4f at 1 spp, %.4f after fxaa (CPU "
        "reference %.4f)\n",
        slope, before, after, cpu);
    // Near-horizontal and near-vertical edges are FXAA's best case (long spans: the end-of-edge
    // search gives each pixel its coverage); at 45 deg the steps are single pixels.
    const float bound = slope < 10.0 || slope > 80.0 ? 0.5f : 0.85f;
    EXPECT_LT(after, bound * before) << slope;
    EXPECT_LT(cpu, bound * before) << slope;
  }
}

class StereoReference : public CoreTest, public ::testing::WithParamInterface<bool> {};

TEST_P(StereoReference, MatchesCpuReference) {
  const bool withDepth = GetParam();
  const uint32_t W = 64, H = 48;
  Params base;
  base.stereoBetaMin = 0.5f;  // a visible blend; the default (0.9) takes at most 10 % of the other eye
  auto f = makeFilter("stereo", base);
  Rig rig(W, H);
  Frame fr;
  fr.views = {eye(0.5f, 0.0f, {-0.032f, 0, 0}), eye(0.5f, 0.0f, {0.032f, 0, 0})};
  fr.color = {pattern(W, H, 11, 0.08f), pattern(W, H, 12, 0.08f)};
  if (withDepth) {
    for (int e = 0; e < 2; ++e) {
      fr.depth[e] = HostImage(W, H);
      for (uint32_t y = 0; y < H; ++y)
        for (uint32_t x = 0; x < W; ++x) {
          const float z = (x > 20 && x < 36 && y > 10 && y < 30) ? 0.4f : 2.0f;  // a box before a wall
          fr.depth[e].at(x, y).r = (1.0f / z - 1.0f / 0.1f) / (1.0f / 100.0f - 1.0f / 0.1f);
        }
    }
  }
  const auto out = rig.run(*f, fr);
  const Params p = *applyMethodName("stereo", base);
  for (int e = 0; e < 2; ++e) {
    const int o = 1 - e;
    const HostImage want =
        test::stereoRef(p, toHalf(fr.color[e]), toHalf(fr.color[o]), fr.views[e], fr.views[o],
                        withDepth ? &fr.depth[e] : nullptr, withDepth ? &fr.depth[o] : nullptr, 0.1f, 100.0f);
    const Diff d = compare(out[e], want);
    EXPECT_LE(d.meanAbs, 3e-3f) << "eye " << e;
    EXPECT_LE(d.maxAbs, 0.08f) << "eye " << e;
    EXPECT_GT(compare(out[e], fr.color[e]).meanAbs, 5e-3f);
  }
}

INSTANTIATE_TEST_SUITE_P(Depth, StereoReference, ::testing::Bool());

// Stereo after a temporal method (seed 002 §5.2: a post pass on both eyes' filtered frames)
// agrees with the stereo reference applied to the temporal result of this frame.
TEST_F(CoreTest, SeparateStereoPassAfterTemporalMatchesReference) {
  const uint32_t W = 48, H = 40;
  const Params p = *applyMethodName("hybrid+stereo");
  std::string err;
  auto f = Filter::create(*gCtx, p, &err);
  ASSERT_TRUE(f) << err;
  Rig rig(W, H);
  Frame f1, f2;
  f1.views = {eye(0.0f, 0.0f, {-0.032f, 0, 0}), eye(0.0f, 0.0f, {0.032f, 0, 0})};
  f1.color = {pattern(W, H, 21, 0.08f), pattern(W, H, 22, 0.08f)};
  f2.views = {eye(0.8f, 0.3f, {-0.032f, 0, 0}), eye(0.8f, 0.3f, {0.032f, 0, 0})};
  f2.color = {pattern(W, H, 23, 0.08f), pattern(W, H, 24, 0.08f)};
  f2.headSpeed = 4.0f;
  rig.run(*f, f1);
  const auto out2 = rig.run(*f, f2);
  std::array<HostImage, 2> temporal;
  for (int e = 0; e < 2; ++e)
    temporal[e] = toHalf(test::temporalRef(p.temporal, p, toHalf(f2.color[e]), toHalf(f1.color[e]), true,
                                           f1.views[e], f2.views[e], f2.headSpeed));
  for (int e = 0; e < 2; ++e) {
    const HostImage want = test::stereoRef(p, temporal[e], temporal[1 - e], f2.views[e], f2.views[1 - e],
                                           nullptr, nullptr, 0.1f, 100.0f);
    const Diff d = compare(out2[e], want);
    EXPECT_LE(d.meanAbs, 3e-3f) << "eye " << e;
    EXPECT_LE(d.maxAbs, 0.08f) << "eye " << e;
  }
}

// Params::invocationBlock: a CPU device runs every pass but fxaa 4x4 pixels per invocation, a GPU
// one pixel. Both layouts must give the same images, on sizes that do not divide by the block (and
// one smaller than a block), on the copy and every temporal mode, with depth (stereo reads both
// eyes' depth).
TEST_F(CoreTest, OnePixelAndBlockInvocationsAgree) {
  for (const auto& [W, H] : {std::pair<uint32_t, uint32_t>{45, 37}, {3, 2}})
    for (const char* method : {"none", "taa+stereo", "hmtaa", "vtaa", "hybrid+stereo"}) {
      std::array<std::array<HostImage, 2>, 2> outs;
      for (int b = 0; b < 2; ++b) {
        Params base;
        base.invocationBlock = b == 0 ? InvocationBlock::OnePixel : InvocationBlock::FourByFour;
        auto f = makeFilter(method, base);
        ASSERT_TRUE(f);
        Rig rig(W, H);
        for (int i = 0; i < 3; ++i) {
          Frame fr;
          const float yaw = 0.6f * float(i);
          fr.views = {eye(yaw, 0.2f * float(i), {-0.032f, 0, 0}), eye(yaw, 0.2f * float(i), {0.032f, 0, 0})};
          fr.color = {pattern(W, H, 40u + 2u * uint32_t(i), 0.1f),
                      pattern(W, H, 41u + 2u * uint32_t(i), 0.1f)};
          for (int e = 0; e < 2; ++e) {
            fr.depth[e] = HostImage(W, H);
            for (uint32_t y = 0; y < H; ++y)
              for (uint32_t x = 0; x < W; ++x) fr.depth[e].at(x, y) = glm::vec4(x < W / 2 ? 0.9f : 0.99f);
          }
          fr.headSpeed = 6.0f;
          outs[size_t(b)] = rig.run(*f, fr);
        }
      }
      for (int e = 0; e < 2; ++e) {
        const Diff d = compare(outs[0][size_t(e)], outs[1][size_t(e)]);
        EXPECT_LE(d.maxAbs, 1e-6f) << method << " " << W << "x" << H << " eye " << e;  // same arithmetic
      }
    }
}

// Params::jitteredInput: the un-jittering fetch at a jitter of 0 reads the texel itself, so the
// layer can use that one pipeline from the first frame on.
TEST_F(CoreTest, JitteredInputWithZeroJitterMatchesPlainFetch) {
  const uint32_t W = 36, H = 28;
  Params jittered;
  jittered.jitteredInput = true;
  auto plain = makeFilter("hybrid+stereo");
  auto withJitterPath = makeFilter("hybrid+stereo", jittered);
  ASSERT_TRUE(plain && withJitterPath);
  Rig rigA(W, H), rigB(W, H);
  for (int i = 0; i < 3; ++i) {
    Frame fr;
    fr.views = {eye(0.4f * float(i), 0.0f, {-0.032f, 0, 0}), eye(0.4f * float(i), 0.0f, {0.032f, 0, 0})};
    fr.color = {pattern(W, H, 70u + uint32_t(i), 0.1f), pattern(W, H, 80u + uint32_t(i), 0.1f)};
    fr.headSpeed = 5.0f;
    const auto a = rigA.run(*plain, fr);
    const auto b = rigB.run(*withJitterPath, fr);
    for (int e = 0; e < 2; ++e) {
      const Diff d = compare(a[size_t(e)], b[size_t(e)]);
      // llvmpipe's bilinear path rounds differently from texelFetch: 1-2 half-float ulps, well
      // below an 8-bit display step (3.9e-3).
      EXPECT_LE(d.maxAbs, 2e-3f) << "frame " << i << " eye " << e;
      EXPECT_LE(d.meanAbs, 2e-4f) << "frame " << i << " eye " << e;
    }
  }
}

// FilterOptions::compileInBackground: frames are refused (compiling() true, the caller passes them
// through) until the pipelines are ready, and never stall for the compile; the first filtered
// frame then matches a synchronously compiled filter's first frame.
TEST_F(CoreTest, BackgroundCompileRefusesFramesUntilReady) {
  const uint32_t W = 40, H = 32;
  const Params p = *applyMethodName("default");
  std::string err;
  FilterOptions background;
  background.compileInBackground = true;
  auto f = Filter::create(*gCtx, p, &err, background);
  ASSERT_TRUE(f) << err;
  auto reference = Filter::create(*gCtx, p, &err);
  ASSERT_TRUE(reference) << err;
  Rig rig(W, H), referenceRig(W, H);
  Frame fr;
  fr.views = {eye(0.3f, 0.1f, {-0.032f, 0, 0}), eye(0.3f, 0.1f, {0.032f, 0, 0})};
  fr.color = {pattern(W, H, 61, 0.05f), pattern(W, H, 62, 0.05f)};
  fr.headSpeed = 3.0f;

  bool submitted = true;
  rig.run(*f, fr, 2, &submitted);
  EXPECT_FALSE(submitted);
  EXPECT_TRUE(f->compiling());
  std::array<HostImage, 2> out;
  for (int i = 0; i < 6000 && !submitted; ++i) {  // a minute at most
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    out = rig.run(*f, fr, 2, &submitted);
  }
  ASSERT_TRUE(submitted);
  EXPECT_FALSE(f->compiling());
  const auto want = referenceRig.run(*reference, fr);
  for (int e = 0; e < 2; ++e) {
    const Diff d = compare(out[size_t(e)], want[size_t(e)]);
    EXPECT_LE(d.maxAbs, 1e-6f) << "eye " << e;
  }
}

// ViewFrame::jitterPx: the temporal passes read the current frame at c - jitter (bilinear), so the
// output and history lie on the unjittered grid.
TEST_F(CoreTest, JitterIsUndoneOnTheUnjitteredGrid) {
  const uint32_t W = 48, H = 32;
  const float kPi = 3.14159265f;
  // A smooth scene f(u, v) in unjittered pixel units; a jittered render holds f(c + g) at pixel c.
  auto scene = [&](float u, float v) {
    return glm::vec4(0.5f + 0.4f * std::sin(2 * kPi * u / 16), 0.5f + 0.4f * std::cos(2 * kPi * v / 12),
                     0.5f + 0.3f * std::sin(2 * kPi * (u + v) / 20), 1.0f);
  };
  auto render = [&](glm::vec2 g) {
    HostImage img(W, H);
    for (uint32_t y = 0; y < H; ++y)
      for (uint32_t x = 0; x < W; ++x) img.at(x, y) = scene(x + 0.5f + g.x, y + 0.5f + g.y);
    return img;
  };
  const HostImage truth = render({0, 0});
  for (const char* m : {"hybrid", "taa", "hmtaa"}) {
    Params p = *applyMethodName(m);
    p.stereo = false;
    std::string err;
    auto f = Filter::create(*gCtx, p, &err);
    ASSERT_TRUE(f) << err;
    Rig rig(W, H);
    const glm::vec2 g(0.37f, -0.29f);
    Frame fr;
    fr.views = {eye(0, 0), eye(0, 0, {0.06f, 0, 0})};
    fr.color = {render(g), render(g)};
    fr.jitter = {g, g};
    const auto first = rig.run(*f, fr);  // no history: the current frame, un-jittered
    HostImage want(W, H);
    for (uint32_t y = 0; y < H; ++y)
      for (uint32_t x = 0; x < W; ++x)
        want.at(x, y) =
            glm::vec4(test::bilinear(toHalf(fr.color[0]), glm::vec2(x + 0.5f, y + 0.5f) - g), 1.0f);
    // Rows/columns at the border clamp to the rect: compare the interior.
    auto interior = [&](const HostImage& a, const HostImage& b) {
      double sum = 0;
      float mx = 0;
      for (uint32_t y = 1; y + 1 < H; ++y)
        for (uint32_t x = 1; x + 1 < W; ++x)
          for (int k = 0; k < 3; ++k) {
            const float d = std::abs(a.at(x, y)[k] - b.at(x, y)[k]);
            sum += d;
            mx = std::max(mx, d);
          }
      return Diff{mx, float(sum / (3.0 * (W - 2) * (H - 2)))};
    };
    EXPECT_LE(interior(first[0], want).maxAbs, 4e-3f) << m;
    const float rawError = interior(fr.color[0], truth).meanAbs;
    EXPECT_LT(interior(first[0], truth).meanAbs, 0.25f * rawError) << m << ": the jittered frame as is";
    // A still head with Halton jitter: the inputs change every frame, the output must not.
    HostImage prev = first[0];
    double outChange = 0, inChange = 0;
    HostImage prevIn = fr.color[0];
    for (uint32_t i = 1; i <= 8; ++i) {
      const glm::vec2 gi(0.5f - std::fmod(0.5f + 0.618034f * float(i), 1.0f),
                         0.5f - std::fmod(0.5f + 0.7548777f * float(i), 1.0f));
      fr.color = {render(gi), render(gi)};
      fr.jitter = {gi, gi};
      const auto out = rig.run(*f, fr);
      outChange += interior(out[0], prev).meanAbs;
      inChange += interior(fr.color[0], prevIn).meanAbs;
      prev = out[0];
      prevIn = fr.color[0];
    }
    EXPECT_LT(outChange, 0.2 * inChange) << m << ": output shimmers with the jitter";
    EXPECT_LT(interior(prev, truth).meanAbs, 0.35f * rawError) << m << ": drifted off the unjittered grid";
  }
}

TEST_F(CoreTest, ConstantColourStaysConstantUnderEveryPass) {
  const uint32_t W = 32, H = 32;
  const glm::vec4 c(0.3f, 0.55f, 0.8f, 1.0f);
  for (const char* m :
       {"none", "fxaa", "taa", "hmtaa", "vtaa", "hybrid", "stereo", "default", "taa+stereo"}) {
    auto f = makeFilter(m);
    Rig rig(W, H, VK_FORMAT_R8G8B8A8_SRGB, VK_FORMAT_R16G16B16A16_SFLOAT);
    const HostImage img(W, H, c);
    const HostImage want =
        rig.run(*f, Frame{{img, img}, {eye(0, 0), eye(0, 0, {0.06f, 0, 0})}})[0];  // sRGB-quantised
    for (int i = 1; i < 5; ++i) {
      Frame fr{{img, img},
               {eye(0.4f * i, -0.2f * i, {0.001f * i, 0, 0}), eye(0.4f * i, -0.2f * i, {0.06f, 0, 0})}};
      fr.headSpeed = 3.0f * float(i);
      const auto out = rig.run(*f, fr);
      for (int e = 0; e < 2; ++e) EXPECT_LE(compare(out[e], want).maxAbs, 2e-3f) << m << " frame " << i;
    }
  }
}

// Seed 002's alpha' does not fall like 1/N: Eq. 11's estimate of E[(X - Y)^2] contains the
// variance of the 3x3 mean (sigma^2 / 9) however well X has converged, so with sigma_Y^2 ~ 8/9
// sigma^2 (Eq. 10, population) alpha' levels off near 1 - (8/9) / (8/9 + 1/9) = 1/9. The noise
// levels off too, higher than a constant 1/9 would keep (1/17 of sigma^2): alpha' fluctuates
// with the noisy 3x3 estimates. Measured: sigma^2 / 9.3 at N = 32 and at N = 64.
TEST_F(CoreTest, VtaaNoiseLevelsOffNearOneNinth) {
  const uint32_t W = 48, H = 48;
  Params p = *applyMethodName("vtaa");
  p.vtaaAlphaMin = 0.0f;  // pure Eq. 4: no floor, so what levels off is Eq. 4's own
  std::string err;
  auto f = Filter::create(*gCtx, p, &err);
  ASSERT_TRUE(f) << err;
  const std::vector<double> mse = noiseMsePerFrame(*f, W, H);
  const double sigma2 = 0.01;
  EXPECT_NEAR(mse[0], sigma2, 0.15 * sigma2);
  // Early on, while (X - mean)^2 dominates, it averages roughly like 1/N ...
  for (int n : {2, 4}) {
    const double ratio = mse[size_t(n - 1)] / (sigma2 / n);
    EXPECT_LT(ratio, 2.0) << "N = " << n << " mse " << mse[size_t(n - 1)];
    EXPECT_GT(ratio, 0.5) << "N = " << n << " mse " << mse[size_t(n - 1)];
  }
  // ... then it stops improving: N = 32 and 64 sit at the same level, near sigma^2 / 9, far
  // above the sigma^2 / 64 of 1/N averaging.
  const double level = sigma2 / 9.0;
  for (int n : {32, 64}) {
    EXPECT_LT(mse[size_t(n - 1)], 1.5 * level) << "N = " << n;
    EXPECT_GT(mse[size_t(n - 1)], 0.67 * level) << "N = " << n;
  }
  EXPECT_GT(mse[63], 2.0 * sigma2 / 64.0) << "not 1/N";
  EXPECT_NEAR(mse[63] / mse[31], 1.0, 0.2) << "levelled off";
}

TEST_F(CoreTest, HeadRotationMovesFeatureByPredictedPixels) {
  // hmtaa with d = 0, w_min = w_lb = 0 and h = 0: A = 0, the output is the reprojected history.
  Params p = *applyMethodName("hmtaa");
  p.wMin = 0.0f;
  p.wLowerBound = 0.0f;
  p.sampleD = {0.0f, 0.0f, 0.0f, 0.0f};
  std::string err;
  auto f = Filter::create(*gCtx, p, &err);
  ASSERT_TRUE(f) << err;
  const uint32_t W = 64, H = 64;
  RefView v0;
  v0.fov = Fov{};  // +-45 deg: tan x = 2 x / W - 1
  const float cx = 20.3f, cy = 32.0f;
  HostImage blob(W, H);
  for (uint32_t y = 0; y < H; ++y)
    for (uint32_t x = 0; x < W; ++x) {
      const float dx = x + 0.5f - cx, dy = y + 0.5f - cy;
      const float v = std::exp(-(dx * dx + dy * dy) / (2 * 2.0f * 2.0f));
      blob.at(x, y) = glm::vec4(v, v, v, 1);
    }
  Rig rig(W, H);
  rig.run(*f, Frame{{blob, blob}, {v0, v0}}, 1);
  RefView v1 = v0;
  const float yaw = 2.0f * kDeg;  // turning left moves the scene right in the image
  v1.pose.orientation = glm::angleAxis(yaw, glm::vec3(0, 1, 0));
  const auto out = rig.run(*f, Frame{{HostImage(W, H), HostImage(W, H)}, {v1, v1}}, 1);
  double sx = 0, sy = 0, sw = 0;
  for (uint32_t y = 0; y < H; ++y)
    for (uint32_t x = 0; x < W; ++x) {
      const double v = out[0].at(x, y).r;
      sx += v * (x + 0.5);
      sy += v * (y + 0.5);
      sw += v;
    }
  // By hand: tan(a) = 2*20.3/64 - 1 = -0.365625, a = -20.0852 deg; after the turn a + 2 deg =
  // -18.0852 deg, tan = -0.326539, x = (1 - 0.326539) * 32 = 21.5508 px (1.25 px to the right).
  const float predicted = (std::tan(std::atan(2 * cx / W - 1) + yaw) + 1) * W / 2;
  EXPECT_NEAR(predicted, 21.5508f, 0.001f);
  EXPECT_NEAR(sx / sw, predicted, 0.05);
  EXPECT_NEAR(sy / sw, cy, 0.05);
}

TEST_F(CoreTest, HmtaaAboveHMaxOutputsCurrentFrameExactly) {
  auto f = makeFilter("hmtaa");
  Rig rig(40, 40, VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_R8G8B8A8_UNORM);
  rig.run(*f, Frame{{pattern(40, 40, 1), pattern(40, 40, 1)}, {eye(0, 0), eye(0, 0)}});
  Frame fr{{pattern(40, 40, 2, 0.1f), pattern(40, 40, 3, 0.1f)}, {eye(0.5f, 0), eye(0.5f, 0)}};
  fr.headSpeed = 25.5f;
  const auto out = rig.run(*f, fr);
  for (int e = 0; e < 2; ++e) {
    // the upload quantised to 8 bits; the output must hold exactly those bytes
    HostImage q = fr.color[e];
    for (auto& px : q.px)
      for (int k = 0; k < 3; ++k) px[k] = std::round(px[k] * 255.0f) / 255.0f;
    EXPECT_EQ(compare(out[e], q).maxAbs, 0.0f);
  }
  Frame fr2{{pattern(40, 40, 4, 0.1f), pattern(40, 40, 5, 0.1f)}, {eye(0.5f, 0), eye(0.5f, 0)}};
  fr2.headSpeed = 10.0f;  // below h_max the history is blended in again
  const auto out2 = rig.run(*f, fr2);
  EXPECT_GT(compare(out2[0], fr2.color[0]).meanAbs, 0.01f);
}

TEST_F(CoreTest, IdenticalEyesAreUnchangedByStereo) {
  // "stereo" alone against the input; "steady+stereo" against its own temporal pass without
  // stereo (steady's first frame is the current frame through its footprint filter).
  for (const auto& [m, without] :
       {std::pair<std::string, std::string>{"stereo", "none"}, {"steady+stereo", "steady"}}) {
    auto f = makeFilter(m);
    auto g = makeFilter(without);
    Rig rig(48, 40, VK_FORMAT_R8G8B8A8_SRGB, VK_FORMAT_R8G8B8A8_SRGB, 0);
    const HostImage img = pattern(48, 40, 13, 0.1f);
    const Frame fr{{img, img}, {eye(0.3f, 0.1f), eye(0.3f, 0.1f)}};
    const auto out = rig.run(*f, fr);
    const auto want = rig.run(*g, fr);
    for (int e = 0; e < 2; ++e) EXPECT_LE(compare(out[e], want[e]).maxAbs, 0.01f) << m;
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
  // size change: a new size starts without history
  Rig small(16, 24);
  const HostImage c = pattern(16, 24, 22);
  EXPECT_LE(compare(small.run(*f, Frame{{c, c}, {eye(40, 0), eye(40, 0)}})[0], c).maxAbs, 1e-3f);
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
