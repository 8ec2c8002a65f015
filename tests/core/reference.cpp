#include "reference.h"

#include <algorithm>
#include <cmath>

#include <glm/glm.hpp>

#include "steadyxr/core/view_math.h"

namespace steadyxr::test {

using glm::vec2;
using glm::vec3;
using glm::vec4;

bool reprojectRef(vec2 pc, float dist, const RefView& from, const RefView& to, glm::uvec2 size, vec2* q,
                  float* distTo) {
  return reprojectRef(pc, dist, from, size, to, size, q, distTo);
}

bool reprojectRef(vec2 pc, float dist, const RefView& from, glm::uvec2 fromSize, const RefView& to,
                  glm::uvec2 size, vec2* q, float* distTo) {
  const glm::mat4 pFrom = core::projectionFromFov(from.fov, 0.1f, 100.0f);
  const vec2 ndc = pc / vec2(fromSize) * 2.0f - 1.0f;
  vec4 v = glm::inverse(pFrom) * vec4(ndc, 0.0f, 1.0f);
  v /= v.w;
  const vec3 pView = vec3(v) * (dist / -v.z);
  const vec4 world = glm::inverse(core::viewFromPose(from.pose)) * vec4(pView, 1.0f);
  const vec4 vt = core::viewFromPose(to.pose) * world;
  if (!(-vt.z > 0.0f)) return false;
  const vec4 clip = core::projectionFromFov(to.fov, 0.1f, 100.0f) * vt;
  *q = (vec2(clip) / clip.w + 1.0f) * 0.5f * vec2(size);
  *distTo = -vt.z;
  return q->x >= 0.0f && q->y >= 0.0f && q->x <= float(size.x) && q->y <= float(size.y);
}

glm::vec3 fetchClamped(const HostImage& img, int x, int y) {
  x = std::clamp(x, 0, int(img.width) - 1);
  y = std::clamp(y, 0, int(img.height) - 1);
  return vec3(img.at(uint32_t(x), uint32_t(y)));
}

glm::vec3 bilinear(const HostImage& img, vec2 q) {
  q = glm::clamp(q, vec2(0.5f), vec2(img.width, img.height) - 0.5f) - 0.5f;
  const vec2 f = q - glm::floor(q);
  const int x = int(std::floor(q.x)), y = int(std::floor(q.y));
  return glm::mix(glm::mix(fetchClamped(img, x, y), fetchClamped(img, x + 1, y), f.x),
                  glm::mix(fetchClamped(img, x, y + 1), fetchClamped(img, x + 1, y + 1), f.x), f.y);
}

glm::vec3 catmullRom5(const HostImage& img, vec2 q) {
  // Separable Catmull-Rom weights of the 4x4 texels around q, with the four corner texels left
  // out and the remaining twelve renormalised (what five bilinear taps can express exactly).
  q = glm::clamp(q, vec2(0.5f), vec2(img.width, img.height) - 0.5f) - 0.5f;
  const vec2 c = glm::floor(q), f = q - c;
  auto weights = [](float t) {
    return vec4(t * (-0.5f + t * (1.0f - 0.5f * t)), 1.0f + t * t * (-2.5f + 1.5f * t),
                t * (0.5f + t * (2.0f - 1.5f * t)), t * t * (-0.5f + 0.5f * t));
  };
  const vec4 wx = weights(f.x), wy = weights(f.y);
  vec3 sum(0);
  float wsum = 0;
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) {
      const bool edgeX = i == 0 || i == 3, edgeY = j == 0 || j == 3;
      if (edgeX && edgeY) continue;
      const float w = wx[i] * wy[j];
      sum += w * fetchClamped(img, int(c.x) + i - 1, int(c.y) + j - 1);
      wsum += w;
    }
  return glm::max(sum / wsum, vec3(0));
}

namespace {

vec3 yCoCg(vec3 c) {
  return {c.r / 4 + c.g / 2 + c.b / 4, c.r / 2 - c.b / 2, -c.r / 4 + c.g / 2 - c.b / 4};
}
vec3 rgb(vec3 y) {
  return {y.x + y.y - y.z, y.x + y.z, y.x - y.y - y.z};
}

float distanceFromDepth(float d, float nearZ, float farZ) {
  const float invZ = 1.0f / nearZ + d * (1.0f / farZ - 1.0f / nearZ);
  return 1.0f / invZ;
}

// Seed 002 Eq. 4 with the literal estimators of Eq. 10 (sigma^2) and Eq. 11 (mean of (X - Y_i)^2).
float eq4Alpha(vec3 x, const vec3 (&n)[9], float lo) {
  vec3 s1(0), s2(0), e(0);
  for (const vec3& y : n) {
    s1 += y;
    s2 += y * y;
    e += (x - y) * (x - y);
  }
  const vec3 var = glm::max(s2 / 9.0f - (s1 / 9.0f) * (s1 / 9.0f), vec3(0));
  const float sigma2 = (var.r + var.g + var.b) / 3.0f;
  const float mse = (e.r + e.g + e.b) / 27.0f;
  const float a = mse > 1e-12f ? 1.0f - sigma2 / mse : 0.0f;
  return std::clamp(a, lo, 1.0f);
}

}  // namespace

HostImage temporalRef(core::TemporalMethod m, const core::Params& p, const HostImage& cur,
                      const HostImage& hist, bool histValid, const RefView& prev, const RefView& now,
                      float headSpeed, const HostImage* depth, float nearZ, float farZ) {
  HostImage out(cur.width, cur.height);
  const glm::uvec2 size(cur.width, cur.height), histSize(hist.width, hist.height);
  const bool interpolated = m == core::TemporalMethod::Hmtaa || m == core::TemporalMethod::Hybrid;
  const uint32_t n = interpolated ? p.sampleCount : 1;
  float w[4];
  core::sampleWeightsW(p.sampleD.data(), n, w);
  const float aGlobal = core::globalWeightA(headSpeed, p.hMaxDegPerSec, p.wMin);
  for (uint32_t y = 0; y < cur.height; ++y)
    for (uint32_t x = 0; x < cur.width; ++x) {
      const vec3 c = vec3(cur.at(x, y));
      vec3 result = c;
      vec3 nb[9];
      for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 3; ++i) nb[j * 3 + i] = fetchClamped(cur, int(x) + i - 1, int(y) + j - 1);
      const float dist = depth ? distanceFromDepth(depth->at(x, y).r, nearZ, farZ) : p.stereoFarDistanceM;
      const vec2 pc(x + 0.5f, y + 0.5f);
      if (histValid) {
        vec3 past(0);
        float wsum = 0;
        for (uint32_t i = 0; i < n; ++i) {
          const RefView at = interpolated
                                 ? RefView{core::interpolatePose(prev.pose, now.pose, p.sampleD[i]), prev.fov}
                                 : prev;
          vec2 q;
          float dt;
          if (reprojectRef(pc, dist, now, size, at, histSize, &q, &dt)) {
            past += w[i] * (p.historyFilter == core::HistoryFilter::CatmullRom ? catmullRom5(hist, q)
                                                                               : bilinear(hist, q));
            wsum += w[i];
          }
        }
        if (wsum > 0) {
          past /= wsum;
          if (m == core::TemporalMethod::Taa) {
            vec3 s1(0), s2(0);
            for (const vec3& v : nb) {
              s1 += yCoCg(v);
              s2 += yCoCg(v) * yCoCg(v);
            }
            const vec3 mean = s1 / 9.0f;
            const vec3 sigma = glm::sqrt(glm::max(s2 / 9.0f - mean * mean, vec3(0)));
            const vec3 ext = p.taaClipGamma * sigma + 1e-6f;
            vec3 h = yCoCg(past);
            const vec3 t = glm::abs(h - mean) / ext;
            const float mx = std::max({t.x, t.y, t.z});
            if (mx > 1.0f) h = mean + (h - mean) / mx;  // clip towards the mean onto the box
            result = glm::max(glm::mix(rgb(h), c, p.taaAlpha), vec3(0));
          } else if (m == core::TemporalMethod::Vtaa) {
            result = glm::mix(past, c, eq4Alpha(past, nb, p.vtaaAlphaMin));
          } else if (m == core::TemporalMethod::Hmtaa) {
            const vec3 dc = c - past;
            const float cdiff = std::clamp(std::sqrt(glm::dot(dc, dc) / 3.0f), 0.0f, 1.0f);
            const float wmin = core::localisedWMin(p.wMin, p.wLowerBound, cdiff);
            const float a = core::globalWeightA(headSpeed, p.hMaxDegPerSec, wmin);
            result = a >= 1.0f ? c : glm::mix(past, c, a);
          } else {
            // Hybrid: history clipped to the YCoCg box mean +- gamma*sigma of the current 3x3,
            // then alpha = max(Eq. 4 of seed 002 for the clipped history, A(h) of seed 003 with
            // w_min = alphaMin), blended with the current frame through the separable
            // [1/16, 7/8, 1/16] footprint filter (the current pixel as is when alpha = 1).
            vec3 s1(0), s2(0);
            for (const vec3& v : nb) {
              s1 += yCoCg(v);
              s2 += yCoCg(v) * yCoCg(v);
            }
            const vec3 mean = s1 / 9.0f;
            const vec3 sigma = glm::sqrt(glm::max(s2 / 9.0f - mean * mean, vec3(0)));
            const vec3 ext = p.taaClipGamma * sigma + 1e-6f;
            vec3 h = yCoCg(past);
            const vec3 t = glm::abs(h - mean) / ext;
            const float mx = std::max({t.x, t.y, t.z});
            if (mx > 1.0f) h = mean + (h - mean) / mx;
            const vec3 clipped = glm::max(rgb(h), vec3(0));
            const float ah = core::globalWeightA(headSpeed, p.hMaxDegPerSec, p.vtaaAlphaMin);
            const float a = std::max(eq4Alpha(clipped, nb, p.vtaaAlphaMin), ah);
            const float k[3] = {1.0f / 16.0f, 7.0f / 8.0f, 1.0f / 16.0f};
            vec3 filtered(0);
            for (int j = 0; j < 3; ++j)
              for (int i = 0; i < 3; ++i) filtered += k[i] * k[j] * nb[j * 3 + i];
            result = a >= 1.0f ? c : glm::mix(clipped, filtered, a);
          }
        }
      }
      (void)aGlobal;
      out.at(x, y) = vec4(result, 1.0f);
    }
  return out;
}

HostImage fxaaRef(const HostImage& in) {
  // FXAA 3.11 "quality" (Lottes 2011, FXAA 3.11 source description; seed 001 §4.3), written from
  // the algorithm's description, in pixel units (centres at +0.5), with its default settings and
  // FXAA_QUALITY__PRESET 25. Luma is sqrt of linear luminance (gamma-like, what FXAA expects of
  // its luma input); colours are sampled bilinearly in linear light, clamped at the borders.
  constexpr float kEdgeThreshold = 0.166f;      // fxaaQualityEdgeThreshold
  constexpr float kEdgeThresholdMin = 0.0833f;  // fxaaQualityEdgeThresholdMin
  constexpr float kSubpix = 0.75f;              // fxaaQualitySubpix
  constexpr float kPreset25[8] = {1.0f, 1.5f, 2.0f, 2.0f, 2.0f, 2.0f, 4.0f, 8.0f};  // P0..P7
  auto luma = [](vec3 c) { return std::sqrt(std::max(glm::dot(c, vec3(0.299f, 0.587f, 0.114f)), 0.0f)); };
  HostImage out(in.width, in.height);
  for (int y = 0; y < int(in.height); ++y)
    for (int x = 0; x < int(in.width); ++x) {
      auto lumaOff = [&](int dx, int dy) { return luma(fetchClamped(in, x + dx, y + dy)); };
      const vec2 posM(x + 0.5f, y + 0.5f);
      const vec3 rgbM = fetchClamped(in, x, y);
      out.at(uint32_t(x), uint32_t(y)) = vec4(rgbM, 1.0f);

      // 1. Local contrast of the cross; low contrast (relative to the brightest, or absolute) exits.
      const float lumaM = luma(rgbM);
      const float lumaN = lumaOff(0, -1), lumaS = lumaOff(0, 1), lumaW = lumaOff(-1, 0),
                  lumaE = lumaOff(1, 0);
      const float rangeMax = std::max({lumaM, lumaN, lumaS, lumaW, lumaE});
      const float rangeMin = std::min({lumaM, lumaN, lumaS, lumaW, lumaE});
      const float range = rangeMax - rangeMin;
      if (range < std::max(kEdgeThresholdMin, rangeMax * kEdgeThreshold)) continue;

      // 2. Sub-pixel aliasing: how far the pixel sits from the 3x3 low-pass (weights 1 2 1 / 2 . 2 /
      //    1 2 1, over 12), relative to the local range, through a smoothstep, squared, times subpix.
      const float lumaNW = lumaOff(-1, -1), lumaNE = lumaOff(1, -1), lumaSW = lumaOff(-1, 1),
                  lumaSE = lumaOff(1, 1);
      const float lowpass =
          (2.0f * (lumaN + lumaS + lumaW + lumaE) + lumaNW + lumaNE + lumaSW + lumaSE) / 12.0f;
      const float subpixC = std::clamp(std::abs(lowpass - lumaM) / range, 0.0f, 1.0f);
      const float subpixF = (3.0f - 2.0f * subpixC) * subpixC * subpixC;
      const float subpixH = subpixF * subpixF * kSubpix;

      // 3. Edge orientation from second differences: across y (rows N, M, S in three columns,
      //    the middle one twice) against across x. A horizontal edge changes along y.
      const float edgeHorz = std::abs(lumaNW - 2.0f * lumaW + lumaSW) +
                             2.0f * std::abs(lumaN - 2.0f * lumaM + lumaS) +
                             std::abs(lumaNE - 2.0f * lumaE + lumaSE);
      const float edgeVert = std::abs(lumaNW - 2.0f * lumaN + lumaNE) +
                             2.0f * std::abs(lumaW - 2.0f * lumaM + lumaE) +
                             std::abs(lumaSW - 2.0f * lumaS + lumaSE);
      const bool horzSpan = edgeHorz >= edgeVert;
      const vec2 across = horzSpan ? vec2(0.0f, 1.0f) : vec2(1.0f, 0.0f);  // step across the edge
      const vec2 along = horzSpan ? vec2(1.0f, 0.0f) : vec2(0.0f, 1.0f);   // search along it

      // 4. The side (negative: N or W; positive: S or E) with the larger gradient is where the edge is.
      const float lumaNeg = horzSpan ? lumaN : lumaW, lumaPos = horzSpan ? lumaS : lumaE;
      const float gradientNeg = std::abs(lumaNeg - lumaM), gradientPos = std::abs(lumaPos - lumaM);
      const bool pairNeg = gradientNeg >= gradientPos;
      const float lengthSign = pairNeg ? -1.0f : 1.0f;
      const float gradientScaled = 0.25f * std::max(gradientNeg, gradientPos);
      const float lumaEdgeAvg = 0.5f * (lumaM + (pairNeg ? lumaNeg : lumaPos));  // 3.11's lumaNN * 0.5

      // 5. Search both ways along the edge, on the line between the pixel and that neighbour,
      //    until the luma there leaves the edge's average by a quarter of the gradient.
      const vec2 posB = posM + across * (0.5f * lengthSign);
      float offN = kPreset25[0], offP = kPreset25[0];
      float lumaEndN = luma(bilinear(in, posB - along * offN)) - lumaEdgeAvg;
      float lumaEndP = luma(bilinear(in, posB + along * offP)) - lumaEdgeAvg;
      bool doneN = std::abs(lumaEndN) >= gradientScaled, doneP = std::abs(lumaEndP) >= gradientScaled;
      for (int level = 1; level < 8 && !(doneN && doneP); ++level) {
        if (!doneN) offN += kPreset25[level];  // the last level moves without sampling
        if (!doneP) offP += kPreset25[level];
        if (level == 7) break;
        if (!doneN) lumaEndN = luma(bilinear(in, posB - along * offN)) - lumaEdgeAvg;
        if (!doneP) lumaEndP = luma(bilinear(in, posB + along * offP)) - lumaEdgeAvg;
        doneN = std::abs(lumaEndN) >= gradientScaled;
        doneP = std::abs(lumaEndP) >= gradientScaled;
      }

      // 6. End-of-edge offset: the nearer end decides; the pixel moves across the edge by
      //    0.5 - distance / span when the luma at that end tells the pixel is on the far side of
      //    the edge's step (otherwise 0), at least the sub-pixel offset.
      const bool nearerN = offN < offP;
      const float lumaEndNearer = nearerN ? lumaEndN : lumaEndP;
      const bool goodSpan = (lumaEndNearer < 0.0f) != (lumaM - lumaEdgeAvg < 0.0f);
      const float pixelOffset = goodSpan ? 0.5f - std::min(offN, offP) / (offN + offP) : 0.0f;
      const float offset = std::max(pixelOffset, subpixH);
      out.at(uint32_t(x), uint32_t(y)) = vec4(bilinear(in, posM + across * (offset * lengthSign)), 1.0f);
    }
  return out;
}

namespace {

// The weight of this eye's estimate after steady (Params::stereoInverseVariance). Each estimate of
// the pixel's area average errs like a sample displaced over the pixel's box (1/12 px^2 per axis)
// averaged over its sample count; the other eye's was also resampled by a bilinear tap at offset
// f (f(1-f) px^2 per axis) and, without depth, displaced by the disparity's spread. Inverse
// variance weights; no blend at all when the spread exceeds a pixel (another surface point).
float inverseVarianceBeta(float countSelf, float countOther, vec2 q, float spreadPx2) {
  if (spreadPx2 > 1.0f) return 1.0f;
  const float boxPx2 = 1.0f / 12.0f + 1.0f / 12.0f;
  const vec2 f = (q - 0.5f) - glm::floor(q - 0.5f);
  const float varSelf = boxPx2 / std::max(countSelf, 1.0f);
  const float varOther =
      boxPx2 / std::max(countOther, 1.0f) + f.x * (1.0f - f.x) + f.y * (1.0f - f.y) + spreadPx2;
  return varOther / (varSelf + varOther);
}

// Without depth the disparity is the far plane's; the true one may be that of a point as near as
// Params::steadyNearestDepthM: the spread in px is focal * |eye offset| * (1/near - 1/far).
float disparitySpreadPx2(const core::Params& p, const RefView& selfView, const RefView& otherView,
                         uint32_t width) {
  const float focalPx = float(width) / (std::tan(selfView.fov.angleRight) - std::tan(selfView.fov.angleLeft));
  const float baseline = glm::length(selfView.pose.position - otherView.pose.position);
  const float px = focalPx * baseline * (1.0f / p.steadyNearestDepthM - 1.0f / p.stereoFarDistanceM);
  return px * px;
}

// Linear interpolation between samples of c one pixel apart, at offset f from the first, gives
// (1-f) c(-f) + f c(1-f) = c + (1/2) f(1-f) c" + O(fourth derivative) (Taylor about the tap
// point). c" is this eye's central second difference per axis (Params::stereoTapCurvature).
vec3 bilinearTapExcess(const HostImage& self, uint32_t x, uint32_t y, vec2 q) {
  const vec2 f = (q - 0.5f) - glm::floor(q - 0.5f);
  const vec3 c = vec3(self.at(x, y));
  const vec3 secondDiffX =
      fetchClamped(self, int(x) - 1, int(y)) + fetchClamped(self, int(x) + 1, int(y)) - 2.0f * c;
  const vec3 secondDiffY =
      fetchClamped(self, int(x), int(y) - 1) + fetchClamped(self, int(x), int(y) + 1) - 2.0f * c;
  return 0.5f * f.x * (1.0f - f.x) * secondDiffX + 0.5f * f.y * (1.0f - f.y) * secondDiffY;
}

HostImage alphaAsColour(const HostImage& img) {
  HostImage a = img;
  for (auto& px : a.px) px = vec4(vec3(px.a), 1.0f);
  return a;
}

}  // namespace

HostImage stereoBlendRef(const core::Params& p, const HostImage& self, const HostImage& stats,
                         bool yCoCgStats, const HostImage& other, const RefView& selfView,
                         const RefView& otherSampleView, const RefView& otherDepthView,
                         const HostImage* selfDepth, const HostImage* otherDepth, float nearZ, float farZ,
                         bool inverseVariance) {
  HostImage out(self.width, self.height);
  const HostImage otherCount = alphaAsColour(other);
  const float spreadPx2 = selfDepth ? 0.0f : disparitySpreadPx2(p, selfView, otherSampleView, self.width);
  auto space = [&](vec3 c) { return yCoCgStats ? yCoCg(c) : c; };
  for (uint32_t y = 0; y < self.height; ++y)
    for (uint32_t x = 0; x < self.width; ++x) {
      const vec3 c = space(vec3(self.at(x, y)));
      vec3 nb[9];
      for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 3; ++i)
          nb[j * 3 + i] = space(fetchClamped(stats, int(x) + i - 1, int(y) + j - 1));
      const float dist =
          selfDepth ? distanceFromDepth(selfDepth->at(x, y).r, nearZ, farZ) : p.stereoFarDistanceM;
      const vec2 pc(x + 0.5f, y + 0.5f);
      const glm::uvec2 otherSize(other.width, other.height);
      vec3 result = c;
      vec2 q;
      float distOther;
      bool ok = reprojectRef(pc, dist, selfView, otherSampleView, otherSize, &q, &distOther);
      if (ok && selfDepth && otherDepth) {
        vec2 qd;
        ok = reprojectRef(pc, dist, selfView, otherDepthView, otherSize, &qd, &distOther);
        if (ok) {
          const int qx = std::clamp(int(std::floor(qd.x)), 0, int(other.width) - 1);
          const int qy = std::clamp(int(std::floor(qd.y)), 0, int(other.height) - 1);
          const float seen = distanceFromDepth(otherDepth->at(uint32_t(qx), uint32_t(qy)).r, nearZ, farZ);
          ok = std::abs(seen - distOther) <= p.stereoDepthTolerance * distOther;
        }
      }
      if (ok) {
        vec3 tap = bilinear(other, q);
        if (inverseVariance && p.stereoTapCurvature)
          tap = glm::max(tap - bilinearTapExcess(self, x, y, q), vec3(0.0f));
        vec3 xo = space(tap);
        // Clip to this eye's box mean +- gamma*sigma (gamma = taaClipGamma; after steady
        // stereoClipGammaAfterSteady), widened to hold this eye's pixel c, towards the mean.
        const float gamma = inverseVariance ? p.stereoClipGammaAfterSteady : p.taaClipGamma;
        vec3 s1(0), s2(0);
        for (const vec3& v : nb) {
          s1 += v;
          s2 += v * v;
        }
        const vec3 mean = s1 / 9.0f;
        const vec3 sigma = glm::sqrt(glm::max(s2 / 9.0f - mean * mean, vec3(0)));
        const vec3 t = glm::abs(xo - mean) / (glm::max(gamma * sigma, glm::abs(c - mean)) + 1e-6f);
        const float mx = std::max({t.x, t.y, t.z});
        if (mx > 1.0f) xo = mean + (xo - mean) / mx;
        const float beta = inverseVariance
                               ? inverseVarianceBeta(self.at(x, y).a, bilinear(otherCount, q).r, q, spreadPx2)
                               : eq4Alpha(xo, nb, p.stereoBetaMin);
        result = glm::mix(xo, c, beta);
      }
      if (yCoCgStats) result = glm::max(rgb(result), vec3(0));
      out.at(x, y) = vec4(result, 1.0f);
    }
  return out;
}

HostImage stereoRef(const core::Params& p, const HostImage& self, const HostImage& other,
                    const RefView& selfView, const RefView& otherView, const HostImage* selfDepth,
                    const HostImage* otherDepth, float nearZ, float farZ, bool inverseVariance) {
  return stereoBlendRef(p, self, self, false, other, selfView, otherView, otherView, selfDepth, otherDepth,
                        nearZ, farZ, inverseVariance);
}

}  // namespace steadyxr::test
