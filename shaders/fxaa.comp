#version 450
#extension GL_GOOGLE_include_directive : require
// FXAA 3.11 quality filter (seed 001 §4.3): luma edge detection, edge-end search along the
// edge with growing steps, sub-pixel aliasing blend. Luma is taken in gamma space (sqrt of
// linear luminance) as FXAA expects; the colour is filtered in linear light.
#include "common.glsl"

// FXAA 3.11's defaults: fxaaQualityEdgeThreshold, fxaaQualityEdgeThresholdMin, fxaaQualitySubpix.
const float kEdgeThreshold = 0.166;
const float kEdgeThresholdMin = 0.0833;
const float kSubpix = 0.75;
// FXAA_QUALITY__PRESET 25: the search samples at the cumulative sums of the first seven steps;
// a side still on the edge after the last sample is assumed to continue one more step.
const int kSteps = 8;
const float kStep[8] = float[8](1.0, 1.5, 2.0, 2.0, 2.0, 2.0, 4.0, 8.0);

vec3 sampleAt(vec2 q) {  // bilinear in src0's rect, q in pixel units (centres at +0.5)
  q = clamp(q, vec2(0.5), vec2(P.src0Size) - 0.5);
  return sanitize(tapSrc0(q).rgb);
}
float luma(vec3 c) { return sqrt(max(dot(c, vec3(0.299, 0.587, 0.114)), 0.0)); }
float lumaAt(vec2 q) { return luma(sampleAt(q)); }

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(p, P.src0Size))) return;
  vec2 pc = vec2(p) + 0.5;
  vec3 rgbM = fetchSrc0(p);
  float lM = luma(rgbM);
  float lN = luma(fetchSrc0(p + ivec2(0, -1)));
  float lS = luma(fetchSrc0(p + ivec2(0, 1)));
  float lW = luma(fetchSrc0(p + ivec2(-1, 0)));
  float lE = luma(fetchSrc0(p + ivec2(1, 0)));
  float lMax = max(max(max(lN, lS), max(lW, lE)), lM);
  float lMin = min(min(min(lN, lS), min(lW, lE)), lM);
  float range = lMax - lMin;
  vec3 result = rgbM;
  if (range >= max(kEdgeThresholdMin, lMax * kEdgeThreshold)) {
    float lNW = luma(fetchSrc0(p + ivec2(-1, -1)));
    float lNE = luma(fetchSrc0(p + ivec2(1, -1)));
    float lSW = luma(fetchSrc0(p + ivec2(-1, 1)));
    float lSE = luma(fetchSrc0(p + ivec2(1, 1)));
    // Second differences across y (large where the edge runs horizontally) and across x.
    float edgeHorz = abs(lNW + lSW - 2.0 * lW) + 2.0 * abs(lN + lS - 2.0 * lM) + abs(lNE + lSE - 2.0 * lE);
    float edgeVert = abs(lNW + lNE - 2.0 * lN) + 2.0 * abs(lW + lE - 2.0 * lM) + abs(lSW + lSE - 2.0 * lS);
    bool horz = edgeHorz >= edgeVert;  // the edge runs horizontally: blend across it in y
    float l1 = horz ? lN : lW;
    float l2 = horz ? lS : lE;
    float g1 = abs(l1 - lM);
    float g2 = abs(l2 - lM);
    bool side1 = g1 >= g2;
    float gradScaled = 0.25 * max(g1, g2);
    float stepLen = side1 ? -1.0 : 1.0;
    float lLocalAvg = 0.5 * ((side1 ? l1 : l2) + lM);
    vec2 across = horz ? vec2(0.0, 1.0) : vec2(1.0, 0.0);
    vec2 along = horz ? vec2(1.0, 0.0) : vec2(0.0, 1.0);
    vec2 q = pc + across * (0.5 * stepLen);  // on the edge between the two pixels
    vec2 q1 = q - along * kStep[0];
    vec2 q2 = q + along * kStep[0];
    float e1 = lumaAt(q1) - lLocalAvg;
    float e2 = lumaAt(q2) - lLocalAvg;
    bool done1 = abs(e1) >= gradScaled;
    bool done2 = abs(e2) >= gradScaled;
    for (int i = 1; i < kSteps; ++i) {
      if (!done1) q1 -= along * kStep[i];
      if (!done2) q2 += along * kStep[i];
      if ((done1 && done2) || i == kSteps - 1) break;  // the last step is not sampled
      if (!done1) e1 = lumaAt(q1) - lLocalAvg;
      if (!done2) e2 = lumaAt(q2) - lLocalAvg;
      done1 = abs(e1) >= gradScaled;
      done2 = abs(e2) >= gradScaled;
    }
    float d1 = dot(pc - q1, along);
    float d2 = dot(q2 - pc, along);
    bool nearer1 = d1 < d2;
    float dist = min(d1, d2);
    float span = d1 + d2;
    float pixelOffset = -dist / span + 0.5;
    bool mLess = (lM - lLocalAvg) < 0.0;
    bool goodSpan = ((nearer1 ? e1 : e2) < 0.0) != mLess;
    float finalOffset = goodSpan ? pixelOffset : 0.0;
    float lAvg = (2.0 * (lN + lS + lW + lE) + lNW + lNE + lSW + lSE) / 12.0;
    float sub1 = clamp(abs(lAvg - lM) / range, 0.0, 1.0);
    float sub2 = (-2.0 * sub1 + 3.0) * sub1 * sub1;
    float subOffset = sub2 * sub2 * kSubpix;
    finalOffset = max(finalOffset, subOffset);
    result = sampleAt(pc + across * (finalOffset * stepLen));
  }
  if (kWriteHist) writeHistory(p, result);
  if (kWriteOut) writeOutput(p, result);
}
