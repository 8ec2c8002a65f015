// What the filter suites share: the Rig, test patterns, eye poses and image comparisons.
#include "filter_test_rig.h"

#include <cmath>
#include <glm/gtc/packing.hpp>
#include <glm/gtc/quaternion.hpp>
#include <random>

namespace steadyxr::test {

using core::DepthRef;
using core::Filter;
using core::Params;
using core::StereoFrame;
using core::StereoOutput;

Rig::Rig(core::VulkanContext& ctx, uint32_t w, uint32_t h, VkFormat inFmt, VkFormat outFmt,
         VkImageUsageFlags outUsage, bool outMutable)
    : w_(w), h_(h) {
  for (int e = 0; e < 2; ++e) {
    in_[e] = std::make_unique<GpuImage>(ctx, inFmt, w, h, 1, VK_IMAGE_USAGE_SAMPLED_BIT);
    out_[e] = std::make_unique<GpuImage>(ctx, outFmt, w, h, 1, outUsage, outMutable);
    depth_[e] = std::make_unique<GpuImage>(ctx, VK_FORMAT_D32_SFLOAT, w, h, 1, VK_IMAGE_USAGE_SAMPLED_BIT);
  }
}

std::array<HostImage, 2> Rig::run(Filter& f, const Frame& fr, uint32_t viewCount, bool* submitted) {
  StereoFrame sf;
  StereoOutput so;
  sf.viewCount = viewCount;
  sf.headSpeedDegPerSec = fr.headSpeed;
  sf.reset = fr.reset;
  for (uint32_t e = 0; e < viewCount; ++e) {
    // A frame smaller than the rig is a rect at the images' top-left corner (an app's dynamic resolution);
    // around it the input holds a bright colour that no pass may read.
    const VkRect2D rect{{0, 0}, {fr.color[e].width, fr.color[e].height}};
    const bool part = rect.extent.width != w_ || rect.extent.height != h_;
    if (part) {
      HostImage around(w_, h_);
      for (auto& px : around.px) px = glm::vec4(8.0f, 0.0f, 8.0f, 1.0f);
      in_[e]->upload(around, 0, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    }
    in_[e]->upload(fr.color[e], 0, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    sf.views[e].color = in_[e]->ref(0, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, rect);
    sf.views[e].pose = fr.views[e].pose;
    sf.views[e].fov = fr.views[e].fov;
    sf.views[e].jitterPx = fr.jitter[e];
    if (!fr.depth[e].px.empty()) {
      depth_[e]->upload(fr.depth[e], 0, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
      DepthRef d;
      d.image = depth_[e]->ref(0, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, rect);
      d.nearZ = 0.1f;
      d.farZ = 100.0f;
      sf.views[e].depth = d;
    }
    so.views[e] = out_[e]->ref(0, outLayout_, rect);
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
    result[e] = out_[e]->download(0, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, 0, 0, fr.color[e].width,
                                  fr.color[e].height);
  return result;
}

std::unique_ptr<Filter> makeFilter(const std::string& method, Params p) {
  auto applied = applyMethodName(method, p);
  EXPECT_TRUE(applied) << method;
  std::string err;
  auto f = Filter::create(*gCtx, *applied, &err);
  EXPECT_TRUE(f) << err;
  return f;
}

HostImage pattern(uint32_t w, uint32_t h, uint32_t seed, float noise) {
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

HostImage toHalf(const HostImage& img) {
  HostImage out = img;
  for (auto& p : out.px)
    for (int k = 0; k < 4; ++k) p[k] = glm::unpackHalf1x16(glm::packHalf1x16(p[k]));
  return out;
}

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

double rmse(const HostImage& a, const HostImage& b) {
  double s = 0.0;
  for (size_t i = 0; i < a.px.size(); ++i)
    for (int k = 0; k < 3; ++k) s += double(a.px[i][k] - b.px[i][k]) * double(a.px[i][k] - b.px[i][k]);
  return std::sqrt(s / (3.0 * double(a.px.size())));
}

Params steadyBoxAlone() {
  Params p = *core::applyMethodName("steady");
  p.steadyNoiseEstimate = false;
  p.steadyGainCompensation = false;
  return p;
}

RefView eye(float yawDeg, float pitchDeg, glm::vec3 pos) {
  RefView v;
  v.pose.orientation =
      glm::angleAxis(yawDeg * kDeg, glm::vec3(0, 1, 0)) * glm::angleAxis(pitchDeg * kDeg, glm::vec3(1, 0, 0));
  v.pose.position = pos;
  v.fov = {-0.75f, 0.70f, 0.72f, -0.80f};  // asymmetric, as headsets report
  return v;
}

}  // namespace steadyxr::test
