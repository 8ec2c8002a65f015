// CPU reference of the steady temporal method, written from its equations (README, method), not
// from shaders/temporal.comp.
#include <algorithm>
#include <cmath>

#include <glm/glm.hpp>

#include "reference.h"
#include "steadyxr/core/view_math.h"

namespace steadyxr::test {

using glm::vec2;
using glm::vec3;
using glm::vec4;

namespace {

vec3 toYCoCg(vec3 c) {
  return {0.25f * c.r + 0.5f * c.g + 0.25f * c.b, 0.5f * c.r - 0.5f * c.b,
          -0.25f * c.r + 0.5f * c.g - 0.25f * c.b};
}
vec3 fromYCoCg(vec3 y) {
  return {y.x + y.y - y.z, y.x + y.z, y.x - y.y - y.z};
}

// The history's sample count at q, resampled with the same filter as its colour.
float countAt(const HostImage& hist, vec2 q, bool catmull) {
  HostImage a(hist.width, hist.height);
  for (size_t i = 0; i < a.px.size(); ++i) a.px[i] = vec4(vec3(hist.px[i].a), 1.0f);
  return catmull ? catmullRom5(a, q).r : bilinear(a, q).r;
}

}  // namespace

HostImage steadyRef(const core::Params& p, const HostImage& cur, const HostImage& hist, bool histValid,
                    const RefView& prev, const RefView& now, const HostImage* depth, float nearZ,
                    float farZ) {
  HostImage out(cur.width, cur.height);
  const glm::uvec2 size(cur.width, cur.height);
  const bool catmull = p.historyFilter == core::HistoryFilter::CatmullRom;
  // The history was rendered from `prev`; the ablation reprojects to a pose between (seed 003).
  const RefView from = p.steadyInterpolated
                           ? RefView{core::interpolatePose(prev.pose, now.pose, p.sampleD[0]), prev.fov}
                           : prev;
  const float maxCount = 1.0f / p.steadyAlphaFloor;
  const float quantVar = (0.5f / 255.0f) * (0.5f / 255.0f);  // half an 8-bit step, squared
  // Without depth: how far apart (px) the history of a point at the far plane and one at the
  // nearest assumed depth lie, for the eye's translation since the last frame.
  float parallaxVar = 0.0f;
  if (!depth && histValid) {
    const float focalPx = float(cur.width) / (std::tan(now.fov.angleRight) - std::tan(now.fov.angleLeft));
    const float e = focalPx * glm::distance(now.pose.position, prev.pose.position) *
                    (1.0f / p.steadyNearestDepthM - 1.0f / p.stereoFarDistanceM);
    parallaxVar = e * e;
  }
  for (uint32_t y = 0; y < cur.height; ++y)
    for (uint32_t x = 0; x < cur.width; ++x) {
      // Mean and (population) variance of the 3x3 neighbourhood in YCoCg.
      vec3 mean(0), meanSq(0);
      for (int j = -1; j <= 1; ++j)
        for (int i = -1; i <= 1; ++i) {
          const vec3 v = toYCoCg(fetchClamped(cur, int(x) + i, int(y) + j));
          mean += v / 9.0f;
          meanSq += v * v / 9.0f;
        }
      const vec3 var = glm::max(meanSq - mean * mean, vec3(0));
      // The current frame's estimate of the pixel's area average: the samples reconstructed with
      // a tent of footprint weight k per side, integrated over the pixel: weights [k, 1-2k, k],
      // applied to the display-like encoding v^(1/2) of the samples (or to v itself), decoded.
      const float k = p.steadyFootprint;
      const float w1d[3] = {k, 1.0f - 2.0f * k, k};
      const float gamma = p.steadyFootprintEncoded ? 2.0f : 1.0f;
      vec3 area(0);
      for (int j = -1; j <= 1; ++j)
        for (int i = -1; i <= 1; ++i)
          area += w1d[i + 1] * w1d[j + 1] *
                  glm::pow(vec3(fetchClamped(cur, int(x) + i, int(y) + j)), vec3(1.0f / gamma));
      area = glm::pow(area, vec3(gamma));
      float distance = p.stereoFarDistanceM;
      if (depth) distance = 1.0f / (1.0f / nearZ + depth->at(x, y).r * (1.0f / farZ - 1.0f / nearZ));
      vec2 q;
      float distPrev = 0;
      const bool confirmed =
          histValid && reprojectRef(vec2(x + 0.5f, y + 0.5f), distance, now, from, size, &q, &distPrev);
      vec3 result = area;
      float count = 1.0f;
      if (confirmed) {
        const vec3 h = toYCoCg(catmull ? catmullRom5(hist, q) : bilinear(hist, q));
        // t: how many (gamma sigma)'s the history lies outside the box, in its worst channel.
        // With steadyClipHoldsCurrent the box reaches, on the history's side, at least as far as the
        // current frame's own estimate `area` of the pixel.
        const vec3 areaY = toYCoCg(area);
        float t = 0.0f;
        for (int ch = 0; ch < 3; ++ch) {
          float box = std::sqrt(p.steadyClipGamma * p.steadyClipGamma * var[ch] + quantVar);
          const bool currentOnHistorySide = (h[ch] - mean[ch]) * (areaY[ch] - mean[ch]) >= 0.0f;
          if (p.steadyClipHoldsCurrent && currentOnHistorySide)
            box = std::max(box, std::abs(areaY[ch] - mean[ch]));
          t = std::max(t, std::abs(h[ch] - mean[ch]) / box);
        }
        const vec3 clipped = t > 1.0f ? mean + (h - mean) / t : h;
        float n = std::clamp(countAt(hist, q, catmull), 0.0f, maxCount);
        if (t > 1.0f && p.steadyClipRejects) n /= t * t;
        float alpha = std::max(1.0f / (n + 1.0f), p.steadyAlphaFloor);
        if (p.steadyBlurBudgetPx2 > 0.0f) {
          // A bilinear tap at offset f within the texel blurs by f(1 - f) per axis; a history blended
          // with weight 1 - alpha every frame settles at (1 - alpha) / alpha times that.
          const vec2 texel = q - 0.5f;
          const vec2 f = texel - glm::floor(texel);
          const float v = f.x * (1.0f - f.x) + f.y * (1.0f - f.y) + parallaxVar;
          alpha = std::max(alpha, v / (v + p.steadyBlurBudgetPx2));
        }
        if (!p.steadyConfidence) alpha = p.taaAlpha;
        result = glm::max(fromYCoCg(glm::mix(clipped, toYCoCg(area), alpha)), vec3(0));
        count = std::min(1.0f / alpha, maxCount);
      }
      out.at(x, y) = vec4(result, count);
    }
  return out;
}

}  // namespace steadyxr::test
