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

// The history's alpha in every channel, so that it resamples with the same filters as its colour.
HostImage alphaImage(const HostImage& hist) {
  HostImage a(hist.width, hist.height);
  for (size_t i = 0; i < a.px.size(); ++i) a.px[i] = vec4(vec3(hist.px[i].a), 1.0f);
  return a;
}

// The history's alpha at q (`alphas`: alphaImage of the history): the sample count, signed by
// round 10's side gate (negative where last frame's history lay above its estimate).
float signedCountAt(const HostImage& alphas, vec2 q, bool catmull) {
  return catmull ? catmullRom5(alphas, q).r : bilinear(alphas, q).r;
}

// The weights of three point samples at positions x[0..2] (px from the pixel centre) whose
// weighted sum has the moments of a footprint centred on the pixel with second moment m2:
// sum w = 1, sum w x = 0, sum w x^2 = m2. The 3x3 Vandermonde system, solved by Cramer's rule.
glm::vec3 momentWeights(const float x[3], float m2) {
  const glm::mat3 v(glm::vec3(1.0f, x[0], x[0] * x[0]), glm::vec3(1.0f, x[1], x[1] * x[1]),
                    glm::vec3(1.0f, x[2], x[2] * x[2]));  // column i: sample i's moments
  const glm::vec3 want(1.0f, 0.0f, m2);
  const float det = glm::determinant(v);
  glm::vec3 w;
  for (int i = 0; i < 3; ++i) {
    glm::mat3 vi = v;
    vi[i] = want;
    w[i] = glm::determinant(vi) / det;
  }
  return w;
}

// Half a step of the 8-bit sRGB input at linear level `linear`, squared (Params::steadyClipQuantSrgb):
// from the level down to the lower edge of the interval of linear values that round to its code
// (IEC 61966-2-1; the curve is convex, so the lower side is the nearer one).
float srgbHalfStepVar(float linear) {
  const double l = std::clamp(double(linear), 0.0, 1.0);
  const double code = 255.0 * (l <= 0.0031308 ? 12.92 * l : 1.055 * std::pow(l, 1.0 / 2.4) - 0.055);
  const double e = std::max(code - 0.5, 0.0) / 255.0;
  const double lowerEdge = e <= 0.04045 ? e / 12.92 : std::pow((e + 0.055) / 1.055, 2.4);
  // At black the interval has no lower side; its upper half (the toe is linear) is as wide.
  const double halfStep = code < 0.5 ? 0.5 / 255.0 / 12.92 : l - lowerEdge;
  return float(halfStep * halfStep);
}

// Item 15 (round 48, Params::steadyResolvedEdges), from the README's statement of it: across the edge is the
// direction d of the 4-neighbour whose display luma differs most from this pixel's (the first of +x, -x, +y,
// -y on a tie); the other three 4-neighbours are within a code of this pixel's display luma (and within an
// eighth of the step); the pixel two across is more than 4 codes away and its own next pixel as flat; the
// pixel between is one coverage c in (1/8, 7/8) of the two sides' colours in every channel (to a code, in the
// display's square root); and 1/z is not affine over the three pixels (second difference above 1e-3 of this
// pixel's 1/z).
bool besideResolvedEdge(const HostImage& cur, const HostImage& depth, int x, int y, float nearZ, float farZ) {
  const float code = 1.0f / 255.0f;
  auto colour = [&](glm::ivec2 at) { return vec3(fetchClamped(cur, x + at.x, y + at.y)); };
  auto luma = [](vec3 c) { return std::sqrt(0.25f * c.r + 0.5f * c.g + 0.25f * c.b); };
  auto invZ = [&](glm::ivec2 at) {
    const int cx = std::clamp(x + at.x, 0, int(depth.width) - 1),
              cy = std::clamp(y + at.y, 0, int(depth.height) - 1);
    return 1.0f / nearZ + depth.at(uint32_t(cx), uint32_t(cy)).r * (1.0f / farZ - 1.0f / nearZ);
  };
  const glm::ivec2 directions[4] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
  const vec3 near = colour({0, 0});
  float offsets[4];
  int across = 0;
  for (int i = 0; i < 4; ++i) {
    offsets[i] = std::abs(luma(colour(directions[i])) - luma(near));
    if (offsets[i] > offsets[across]) across = i;
  }
  const glm::ivec2 d = directions[across];
  const vec3 between = colour(d), far = colour(2 * d);
  const float stepAcross = luma(far) - luma(near);
  const float flat = std::min(std::abs(stepAcross) / 8.0f, code);
  bool nearSideFlat = true;
  for (int i = 0; i < 4; ++i)
    if (i != across && offsets[i] >= flat) nearSideFlat = false;
  const bool farSideFlat = std::abs(luma(colour(3 * d)) - luma(far)) < flat;
  if (std::abs(stepAcross) <= 4.0f * code || !nearSideFlat || !farSideFlat) return false;
  const vec3 s = far - near;
  const float c = glm::dot(between - near, s) / std::max(glm::dot(s, s), 1e-12f);
  const vec3 oneMix = glm::max(near + c * s, vec3(0.0f));
  const vec3 off = glm::abs(glm::sqrt(between) - glm::sqrt(oneMix));
  if (c <= 0.125f || c >= 0.875f || std::max({off.r, off.g, off.b}) >= code) return false;
  const float secondDifference = invZ({0, 0}) - 2.0f * invZ(d) + invZ(2 * d);
  return std::abs(secondDifference) > 1e-3f * std::abs(invZ({0, 0}));
}

}  // namespace

HostImage steadyRef(const core::Params& p, const HostImage& cur, const HostImage& hist, bool histValid,
                    const RefView& prev, const RefView& now, const HostImage* depth, float nearZ, float farZ,
                    glm::vec2 jitterPx, bool srgbInput) {
  HostImage out(cur.width, cur.height);
  const glm::uvec2 size(cur.width, cur.height), histSize(hist.width, hist.height);
  const bool catmull = p.historyFilter == core::HistoryFilter::CatmullRom;
  // The history was rendered from `prev`; the ablation reprojects to a pose between (seed 003).
  const RefView from = p.steadyInterpolated
                           ? RefView{core::interpolatePose(prev.pose, now.pose, p.sampleD[0]), prev.fov}
                           : prev;
  const float maxCount = 1.0f / p.steadyAlphaFloor;
  const HostImage alphas = alphaImage(hist);                 // once per frame, not per pixel
  const float quantVar = (0.5f / 255.0f) * (0.5f / 255.0f);  // half an 8-bit step, squared
  // The render's noise, told (Params::steadyNoiseVariance; the host's estimate is checked in
  // steady_noise_test.cpp): the box widened by one pixel's noise in each YCoCg channel. Independent
  // RGB channels of variance v give a linear combination with row r the variance v |r|^2.
  vec3 noiseVar(0.0f);
  if (!p.steadyNoiseEstimate && p.steadyNoiseVariance > 0.0f)
    for (int rgb = 0; rgb < 3; ++rgb) {
      vec3 unit(0.0f);
      unit[rgb] = 1.0f;
      const vec3 row = toYCoCg(unit);  // this RGB channel's weight in Y, Co, Cg
      noiseVar += p.steadyNoiseVariance * row * row;
    }
  for (uint32_t y = 0; y < cur.height; ++y)
    for (uint32_t x = 0; x < cur.width; ++x) {
      // Jittered input (a jitter of exactly (0, 0) is an unjittered frame): sample (i, j) of the
      // 3x3 lies at (i, j) + jitterPx from this pixel's centre.
      const bool jittered = jitterPx != vec2(0.0f);
      const float xs[3] = {jitterPx.x - 1.0f, jitterPx.x, jitterPx.x + 1.0f};
      const float ys[3] = {jitterPx.y - 1.0f, jitterPx.y, jitterPx.y + 1.0f};
      // Mean and (population) variance of the 3x3 neighbourhood in YCoCg: equal weights 1/3 per
      // axis, or on jittered input the weights with the same moments about this pixel's centre
      // (first 0, second 2/3) at the samples' positions.
      const vec3 cx = jittered ? momentWeights(xs, 2.0f / 3.0f) : vec3(1.0f / 3.0f);
      const vec3 cy = jittered ? momentWeights(ys, 2.0f / 3.0f) : vec3(1.0f / 3.0f);
      vec3 mean(0), meanSq(0);
      for (int j = -1; j <= 1; ++j)
        for (int i = -1; i <= 1; ++i) {
          const vec3 v = toYCoCg(fetchClamped(cur, int(x) + i, int(y) + j));
          mean += cx[i + 1] * cy[j + 1] * v;
          meanSq += cx[i + 1] * cy[j + 1] * v * v;
        }
      const vec3 var = glm::max(meanSq - mean * mean, vec3(0));
      // The current frame's estimate of the pixel's area average: the samples reconstructed with
      // a tent of footprint weight k per side, integrated over the pixel: weights [k, 1-2k, k],
      // applied to the display-like encoding v^(1/2) of the samples (or to v itself), decoded.
      const float k = p.steadyFootprint;
      vec3 wx(k, 1.0f - 2.0f * k, k), wy = wx;
      // Jittered: either the weights that give the footprint's moments (0, 2k) about the centre
      // per axis, or the sample inside this pixel alone (the jitter, uniform over the pixel, makes
      // the running mean its box average).
      if (jittered) {
        wx = p.steadyJitterRecentred ? momentWeights(xs, 2.0f * k) : vec3(0.0f, 1.0f, 0.0f);
        wy = p.steadyJitterRecentred ? momentWeights(ys, 2.0f * k) : vec3(0.0f, 1.0f, 0.0f);
      }
      const float gamma = p.steadyFootprintEncoded ? 2.0f : 1.0f;
      vec3 area(0);
      for (int j = -1; j <= 1; ++j)
        for (int i = -1; i <= 1; ++i)
          area += wx[i + 1] * wy[j + 1] *
                  glm::pow(vec3(fetchClamped(cur, int(x) + i, int(y) + j)), vec3(1.0f / gamma));
      area = glm::pow(glm::max(area, vec3(0.0f)), vec3(gamma));
      // Item 15: beside an edge the app resolved, its own sample (no footprint) and no blur budget.
      const bool resolvedEdge = p.steadyResolvedEdges && depth && !jittered &&
                                besideResolvedEdge(cur, *depth, int(x), int(y), nearZ, farZ);
      if (resolvedEdge) area = vec3(fetchClamped(cur, int(x), int(y)));
      float distance = p.stereoFarDistanceM;
      if (depth) distance = 1.0f / (1.0f / nearZ + depth->at(x, y).r * (1.0f / farZ - 1.0f / nearZ));
      vec2 q;
      float distPrev = 0;
      const bool confirmed = histValid && reprojectRef(vec2(x + 0.5f, y + 0.5f), distance, now, size, from,
                                                       histSize, &q, &distPrev);
      vec3 result = area;
      float count = 1.0f;
      if (confirmed) {
        const vec3 h = toYCoCg(catmull ? catmullRom5(hist, q) : bilinear(hist, q));
        // Round 10's option (off by default): the one-sided box only where the history's luma lies on the
        // same side of this frame's estimate `area` as it did last frame (kept in the sign of the alpha).
        const float signedCount = signedCountAt(alphas, q, catmull);
        const bool gated =
            p.steadyClipCurvatureCentredGated && p.historyFormat == core::HistoryFormat::Rgba16f;
        const bool above = h.x > toYCoCg(area).x;
        const bool sameSideAsLastFrame = above == (signedCount < 0.0f);
        // t: how many (gamma sigma)'s the history lies outside the box, in its worst channel.
        // With steadyClipHoldsCurrent the box reaches, on the history's side, at least as far as the
        // current frame's own estimate `area` of the pixel.
        const vec3 areaY = toYCoCg(area);
        // With steadyClipCurvature the box is no wider than kappa (|cxx| + |cyy|): the second
        // differences of the current frame along x and y through this pixel's sample.
        auto at = [&](int i, int j) { return toYCoCg(vec3(fetchClamped(cur, int(x) + i, int(y) + j))); };
        const vec3 cxx = at(-1, 0) - 2.0f * at(0, 0) + at(1, 0);
        const vec3 cyy = at(0, -1) - 2.0f * at(0, 0) + at(0, 1);
        float t = 0.0f;
        vec3 centre = mean;  // the box's centre
        for (int ch = 0; ch < 3; ++ch) {
          const float sigmaVar = p.steadyClipGamma * p.steadyClipGamma * var[ch];
          float boxVar = sigmaVar;
          if (p.steadyClipCurvature) {
            const float secondOrder = p.steadyClipCurvatureKappa * (std::abs(cxx[ch]) + std::abs(cyy[ch]));
            boxVar = std::min(boxVar, secondOrder * secondOrder);
            if (p.steadyClipCurvatureCentred && (!gated || sameSideAsLastFrame)) {
              // A static history blurred by V per axis lies (V/2 - 1/3) c'' from the 3x3 mean, with
              // 1/3 - V/2 between inner and kappa: per axis the interval between -kappa c'' and
              // -inner c'', summed over x and y. It is the box where it is narrower than gamma sigma.
              float lo = 0.0f, hi = 0.0f;
              for (const float c : {cxx[ch], cyy[ch]}) {
                lo += std::min(-p.steadyClipCurvatureKappa * c, -p.steadyClipCurvatureInner * c);
                hi += std::max(-p.steadyClipCurvatureKappa * c, -p.steadyClipCurvatureInner * c);
              }
              const float halfWidth = 0.5f * (hi - lo);
              boxVar = sigmaVar;
              if (halfWidth * halfWidth <= sigmaVar) {
                centre[ch] = mean[ch] + 0.5f * (lo + hi);
                boxVar = halfWidth * halfWidth;
              }
            }
          }
          float box =
              std::sqrt(boxVar + (p.steadyClipQuantSrgb && srgbInput ? srgbHalfStepVar(mean.x) : quantVar) +
                        noiseVar[ch]);
          const bool currentOnHistorySide = (h[ch] - centre[ch]) * (areaY[ch] - centre[ch]) >= 0.0f;
          if (p.steadyClipHoldsCurrent && currentOnHistorySide)
            box = std::max(box, std::abs(areaY[ch] - centre[ch]));
          t = std::max(t, std::abs(h[ch] - centre[ch]) / box);
        }
        const vec3 clipped = t > 1.0f ? centre + (h - centre) / t : h;
        float n = std::clamp(std::abs(signedCount), 0.0f, maxCount);
        if (t > 1.0f && p.steadyClipRejects) n /= t * t;
        float alpha = std::max(1.0f / (n + 1.0f), p.steadyAlphaFloor);
        if (p.steadyBlurBudgetPx2 > 0.0f) {
          // A bilinear tap at offset f within the texel blurs by f(1 - f) per axis; a history blended
          // with weight 1 - alpha every frame settles at (1 - alpha) / alpha times that.
          // The budget is the box footprint's variance summed over x and y (1/12 + 1/12). Per
          // axis: each axis's blur against its half, the worse one decides.
          const vec2 texel = q - 0.5f;
          const vec2 f = texel - glm::floor(texel);
          // In this frame's pixels: a history texel of another render size spans size / histSize of them
          // per axis, and a variance scales with the square of the length.
          const vec2 span = vec2(size) / vec2(histSize);
          const float vx = f.x * (1.0f - f.x) * span.x * span.x, vy = f.y * (1.0f - f.y) * span.y * span.y;
          const float v = p.steadyHistoryBlurPerAxis ? 2.0f * std::max(vx, vy) : vx + vy;
          float guard = v / (v + p.steadyBlurBudgetPx2);
          if (p.steadyBlurNoiseTrade && p.steadyHistoryBlurPerAxis && noiseVar.x > 0.0f) {
            // Round 26, per axis: an exponential mean of weight alpha holds alpha / (2 - alpha) of the
            // frames' noise variance s2 (its luma's, noiseVar.x) and, blurred by B = (1 - alpha) / alpha * w
            // (w this frame's tap blur on the axis), is off a curved signal by B c'' / 2. For small alpha
            // the sum s2 alpha / 2 + (w c'' / (2 alpha))^2 is least where its derivative
            // s2 / 2 - w^2 c''^2 / (2 alpha^3) is 0: alpha = cbrt(w^2 c''^2 / s2). c''^2 is the luma's
            // second difference squared less its noise, (1 + 4 + 1) s2; B at most 1/4 px^2, where two
            // of its standard deviations reach the 3x3's edge; never above the axis's own guard, which
            // holds B to half the budget.
            guard = 0.0f;
            const float axisBlur[2] = {vx, vy}, curvature[2] = {cxx.x, cyy.x};
            for (int axis = 0; axis < 2; ++axis) {
              const float w = axisBlur[axis];
              const float signal2 = std::max(curvature[axis] * curvature[axis] - 6.0f * noiseVar.x, 0.0f);
              const float least = std::max(std::cbrt(w * w * signal2 / noiseVar.x), w / (w + 0.25f));
              guard = std::max(guard, std::min(least, w / (w + 0.5f * p.steadyBlurBudgetPx2)));
            }
          }
          alpha = std::max(alpha, guard);
        }
        if (resolvedEdge) {  // the blurrier axis's f(1 - f), both axes' worth, against 1e-4 px^2
          const vec2 f = (q - 0.5f) - glm::floor(q - 0.5f), span = vec2(size) / vec2(histSize);
          const vec2 axis = f * (1.0f - f) * span * span;
          const float v = 2.0f * std::max(axis.x, axis.y);
          alpha = std::max(alpha, v / (v + 1e-4f));
        }
        if (!p.steadyConfidence) alpha = p.taaAlpha;
        result = glm::max(fromYCoCg(glm::mix(clipped, toYCoCg(area), alpha)), vec3(0));
        count = std::min(1.0f / alpha, maxCount);
        if (gated && p.steadyClipCurvature && p.steadyClipCurvatureCentred && above) count = -count;
      }
      out.at(x, y) = vec4(result, count);
    }
  return out;
}

}  // namespace steadyxr::test
