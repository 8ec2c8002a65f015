#version 450
#extension GL_GOOGLE_include_directive : require
// Temporal passes: taa (mode 0), hmtaa (1), vtaa (2), hybrid (3), steady (4). Writes the new
// history (RGBA16F or RGBA8 sqrt-encoded: storeHistory; steady keeps its per-pixel sample count in the
// alpha) and, when no stereo pass follows, the output.
#include "common.glsl"
#include "resolved_edge.glsl"

const int kTaa = 0;
const int kHmtaa = 1;
const int kVtaa = 2;
const int kHybrid = 3;
const int kSteady = 4;
// Smallest clip extent, as a variance: half an 8-bit step squared. A flat 3x3 has sigma = 0, and
// a history off by less than the input's own quantisation is no evidence of a wrong history.
const float kQuantVar = (0.5 / 255.0) * (0.5 / 255.0);
const float kIecSlopeScale2 = (2.4 / 1.055) * (2.4 / 1.055);  // the sRGB curve's 2.4 / 1.055, squared
// Round 13 (Params::steadyNoiseEstimate): the clip box widened by the render's noise (kSteadyBoxSwitches
// bit 3) and the histogram that estimates it (bit 4, round 14's residual bit 5;
// layer/core/src/noise_estimate.h, the same constants). Since round 22 the probe (bit 7) takes the
// samples, not the pass: the residual's 5x5 and 16 history texels, in the pass, tripled its registers
// for every pixel (RADV's compiler: 60 -> 137 VGPRs, a quarter of the waves per SIMD), for the one
// pixel in 16 that samples.
const bool kNoiseAware = kMode == 4 && (kSteadyBoxSwitches & 8) != 0;
const bool kBlurNoiseTrade = kNoiseAware && (kSteadyBoxSwitches & 1024) != 0;  // round 26: bit 10
const int kNoiseBins = 64;
const int kNoiseHistograms = 2;
const int kResidualSums = 2;  // after the histograms (round 15)
// The record's copies, by workgroup, each on 64-byte lines of its own (noise_estimate.h, kNoiseCopies).
const int kNoiseCopies = 8;
const int kNoiseCopyStride = (kNoiseHistograms * kNoiseBins + kResidualSums + 15) / 16 * 16;
uint noiseCopyBase() { return uint(kNoiseCopyStride) * (gl_WorkGroupID.x % uint(kNoiseCopies)); }
// Round 16 (Params::steadyGainCompensation): the frame's gain, probed before the pass (bit 7: this
// dispatch is the probe, probeFrame; bit 6: with the gain's sums) and read by it (bit 6: frameGain, once
// per invocation). The probe's record follows the noise record's copies, on a 16-word line of its own
// (noise_estimate.h, kGainRecordWords and on: 4 words). Round 17 (Params::steadyGainRelightsAdmitted,
// bit 8): also where the box admits the history, in a frame whose change the gain explains.
const bool kGainCompensated = kMode == 4 && (kSteadyBoxSwitches & 64) != 0;
const uint kGainBase = uint(kNoiseCopies * kNoiseCopyStride);
const float kLumaSumScale = 1024.0;
const float kPi = 3.14159265358979;
const float kNoiseBinsPerOctave = 4.0;
const float kNoiseLowestLog2 = -16.0;
layout(set = 0, binding = 9, std430) buffer NoiseHistogram { uint noiseBins[]; };

vec3 toYCoCg(vec3 c) {
  return vec3(0.25 * c.r + 0.5 * c.g + 0.25 * c.b, 0.5 * c.r - 0.5 * c.b, -0.25 * c.r + 0.5 * c.g - 0.25 * c.b);
}
vec3 fromYCoCg(vec3 y) { return vec3(y.x + y.y - y.z, y.x + y.z, y.x - y.y - y.z); }
// Sum of toYCoCg(c)^2 from the sums of c*c (s2) and of (rg, rb, gb) (sx).
vec3 yCoCgSquares(vec3 s2, vec3 sx) {
  return vec3(0.0625 * s2.r + 0.25 * s2.g + 0.0625 * s2.b + 0.25 * sx.x + 0.125 * sx.y + 0.25 * sx.z,
              0.25 * s2.r + 0.25 * s2.b - 0.5 * sx.y,
              0.0625 * s2.r + 0.25 * s2.g + 0.0625 * s2.b - 0.25 * sx.x + 0.125 * sx.y - 0.25 * sx.z);
}

// No texture read under a condition (see PROCESS_BLOCK): invalid samples are weighted out.
void addSample(mat4 m, float w, vec2 pc, float invZ, inout vec3 past, inout float wsum) {
  vec2 q;
  float iz;
  float wv = reproject(m, pc, invZ, q, iz) ? w : 0.0;
  past += wv * sampleHistory(q);  // q is clamped into the image inside
  wsum += wv;
}

// Seed 003 Eq. 1/2: W-weighted sum of the interpolated reprojections; false if none is valid.
// Constant array indices (no loop): llvmpipe turns a dynamically indexed UBO matrix into gathers.
bool pastColour(vec2 pc, float invZ, out vec3 past) {
  past = vec3(0.0);
  float wsum = 0.0;
  addSample(P.reproj[0], P.sampleWeights[0], pc, invZ, past, wsum);
  if (kSampleCount > 1) addSample(P.reproj[1], P.sampleWeights[1], pc, invZ, past, wsum);
  if (kSampleCount > 2) addSample(P.reproj[2], P.sampleWeights[2], pc, invZ, past, wsum);
  if (kSampleCount > 3) addSample(P.reproj[3], P.sampleWeights[3], pc, invZ, past, wsum);
  past = wsum > 0.0 ? past * (1.0 / wsum) : vec3(0.0);  // renormalise over the samples inside the image
  return wsum > 0.0;
}

// Seed 002 Eq. 4 with Eq. 10 (sigma^2 of the 3x3) and Eq. 11 (mean of (X - Y_i)^2), averaged
// over RGB. Uses sum_i (X - Y_i)^2 / 9 = (X - mean)^2 + sigma^2 (population estimators).
float varianceAlpha(vec3 x, vec3 mean, vec3 var) {
  float s2 = max((var.r + var.g + var.b) * (1.0 / 3.0), 0.0);
  vec3 d = x - mean;
  float e = dot(d, d) * (1.0 / 3.0) + s2;
  float a = e > 1e-12 ? 1.0 - s2 / e : 0.0;
  return clamp(a, P.alphaMin, 1.0);
}

// Steady on jittered input: tap i of a 3x3 row is a point sample at x = i + j from this pixel's
// centre (j = jitterPx; src0's pixel c holds our point c + j), the centre tap inside this pixel.
// Weights recentred on the pixel, per axis: sum w = 1, sum w x = 0, sum w x^2 = m2, so
// w(-1) = (m2 + j^2 + j) / 2, w(0) = 1 - m2 - j^2, w(1) = (m2 + j^2 - j) / 2 ([m2/2, 1 - m2, m2/2]
// at j = 0).
vec3 recentredWeights(float j, float m2) {
  const float s = m2 + j * j;
  return vec3(0.5 * (s + j), 1.0 - s, 0.5 * (s - j));
}
// The current frame's estimate of the pixel's area average from jittered taps, in linear light or
// on square roots (Params::steadyFootprintEncoded), as the unjittered footprint. With
// Params::steadyJitterRecentred the footprint's moments (m2 = 2k) about the pixel centre;
// otherwise the centre tap alone: with j spread uniformly over the pixel (Halton), the running
// mean of the sample inside the pixel converges to the pixel's box average (Karis 2014).
vec3 jitteredFootprint(ivec2 o, float k) {
  const bool recentred = P.steadyJitterRecentred > 0.5;
  const vec3 wx = recentred ? recentredWeights(P.jitterPx.x, 2.0 * k) : vec3(0.0, 1.0, 0.0);
  const vec3 wy = recentred ? recentredWeights(P.jitterPx.y, 2.0 * k) : vec3(0.0, 1.0, 0.0);
  vec3 linear = vec3(0.0), encoded = vec3(0.0);
  [[unroll]] for (int y = -1; y <= 1; ++y)
    [[unroll]] for (int x = -1; x <= 1; ++x) {
      const vec3 c = blockAt(o, x, y);
      const float w = wx[x + 1] * wy[y + 1];
      linear += w * c;
      encoded += w * sqrt(c);
    }
  encoded = max(encoded, vec3(0.0));  // the negative weights (|j| near 1/2) may undershoot
  return max(P.steadyFootprintEncoded > 0.5 ? encoded * encoded : linear, vec3(0.0));
}
// Steady's clip box on jittered input: the YCoCg mean and variance of the 3x3 with the weights
// recentred on the pixel, with the plain 3x3's second moment (m2 = 2/3; all weights >= 0 for
// |j| <= 1/2). The plain mean is the picture at +j; the history estimates it at the centre.
void recentredClipMoments(ivec2 o, out vec3 mean, out vec3 variance) {
  const vec3 wx = recentredWeights(P.jitterPx.x, 2.0 / 3.0), wy = recentredWeights(P.jitterPx.y, 2.0 / 3.0);
  vec3 m1 = vec3(0.0), m2 = vec3(0.0);
  [[unroll]] for (int y = -1; y <= 1; ++y)
    [[unroll]] for (int x = -1; x <= 1; ++x) {
      const vec3 c = toYCoCg(blockAt(o, x, y));
      const float w = wx[x + 1] * wy[y + 1];
      m1 += w * c;
      m2 += w * c * c;
    }
  mean = m1;
  variance = max(m2 - m1 * m1, vec3(0.0));
}

// The history's texel t (linear colour), either encoding.
vec3 historyTexel(ivec2 t) {
  if (kHistoryEncoding != 0) return history8Texel(t).rgb;
  return texelFetch(uSrc1, P.src1Offset + clamp(t, ivec2(0), P.src1Size - 1), 0).rgb;
}
// Steady's estimate of the pixel from its 3x3 through the footprint [k, 1 - 2k, k]^2 (README item 4), in
// linear light or on square roots (Params::steadyFootprintEncoded): the centre, the sum of the edge
// neighbours and the 3x3's sum, and the same two sums of square roots with the corners'. The pass and the
// probe both call it, with their sums in the same order, so that the probe's residual is the pass's.
vec3 footprintEstimate(vec3 centre, vec3 edges, vec3 sum3x3, vec3 sqrtEdges, vec3 sqrtCorners, float k,
                       bool encoded) {
  const vec3 linear = (1.0 - 2.0 * k) * (1.0 - 2.0 * k) * centre + k * (1.0 - 2.0 * k) * edges +
                      k * k * (sum3x3 - centre - edges);
  const vec3 g =
      (1.0 - 2.0 * k) * (1.0 - 2.0 * k) * sqrt(centre) + k * (1.0 - 2.0 * k) * sqrtEdges + k * k * sqrtCorners;
  return encoded ? g * g : linear;
}
// The box's floor (Params::steadyClipQuantSrgb, processPixel) as a variance over kQuantVar at luma `level`:
// IEC 61966-2-1's slope d(linear)/d(code) squared, bounded from below, for sRGB input; 1 for linear.
float floorSlope2(float level) {
  level = clamp(level, 0.0, 1.0);
  const float srgbSlope2 = max(kIecSlopeScale2 * level * sqrt(sqrt(level)), 1.0 / (12.92 * 12.92));
  return (kSteadyBoxSwitches & 2) != 0 ? srgbSlope2 : 1.0;
}

#include "probe.glsl"

// The frame's gain from the probe's record: this frame's luma over the history's where the mean of
// their difference lies 4 standard errors or more from 0 (round 15's test, noise_estimate.h,
// kChangeTestStandardErrors: sigma = sqrt(pi / 2) E|r|); 1 elsewhere. Round 17: whether the gain explains
// the frame's change d (this frame's luma less the history's) and is more than the input's rounding: a
// mean |d| of at least half a step of the 8-bit input at the history's mean luma (the box's floor: less is
// no evidence), and |sum d| >= 1/2 sum |d|. A gain moves every sample the same way (|sum d| = sum |d|);
// structure that moves (a video's zoom, content that slides) and noise move samples both ways and
// cancel in the sum. (The footprint filter on square roots leaves a still picture's history 0.07 % dark:
// significant, one-signed, and well under the floor.)
bool gGainExplains = false;
// Round 31 (Params::steadyUnexplainedFrameResets, bit 11): a frame its pose does not explain. Where the
// history's 4x4 blocks, reprojected through the pose, differ from the frame's by more than the frame's
// blocks differ from their neighbours a block away, the history is misplaced by about a block or more as a
// whole (a ramp shifted s px differs by s / 4 of a block's step): the app moved its rig (a snap turn) and
// submitted the tracked head's pose, or the pose is wrong. Every pixel then starts afresh, as after a
// disocclusion: a box cannot tell a misplaced repeating texture from its own content. On blocks, not
// pixels: a thin wire that the point samples miss in one frame and hit in the next changes its pixels by
// more than their steps, under a pose that explains it; a block holds its coverage. Not where the gain
// explains the change (a fade; since round 33, one that keeps the history's structure), and not where the
// blocks' change is under the box's floor (rounding).
bool gPoseUnexplained = false;
float frameGain() {
  const uint current = noiseBins[kGainBase], history = noiseBins[kGainBase + 1];
  const uint magnitude = noiseBins[kGainBase + 2], samples = noiseBins[kGainBase + 3];
  if (samples < 2u || magnitude == 0u || history == 0u) return 1.0;
  const float n = float(samples);
  const float meanDifference = float(int(current - history)) / (kLumaSumScale * n);
  const float standardError = sqrt(0.5 * kPi) * float(magnitude) / (kResidualSumScale * n) * inversesqrt(n);
  const bool significant = abs(meanDifference) >= 4.0 * standardError;
  const float meanMagnitude = float(magnitude) / (kResidualSumScale * n);
  const float historyMean = float(history) / (kLumaSumScale * n);
  const bool relightsAdmitted = (kSteadyBoxSwitches & 256) != 0;  // spelled out: see main
  gGainExplains = relightsAdmitted && meanDifference * meanDifference >= kQuantVar * floorSlope2(historyMean) &&
                  abs(meanDifference) >= 0.5 * meanMagnitude;
  const float meanChange = float(noiseBins[kGainBase + 4]) / (kResidualSumScale * n);
  const float meanStep = float(noiseBins[kGainBase + 5]) / (kResidualSumScale * n);
  const bool resets = (kSteadyBoxSwitches & 2048) != 0;  // spelled out: see main
  // Noise alone gives a change <= the step (a history as noisy as the frame: equal), so the test is that
  // the change exceeds the step by 4 standard errors of their ratio (each mean's relative error a
  // half-normal's, sqrt(pi / 2 - 1) / sqrt(n); the ratio's at most sqrt(2) times that): 1.09 at 2048 samples.
  const float ratioStandardError = sqrt(2.0 * (0.5 * kPi - 1.0)) * inversesqrt(n);
  const bool changeAboveFloor = meanChange * meanChange >= kQuantVar * floorSlope2(historyMean);
  // Round 33: a change the gain explains (one-signed, as gGainExplains) is a fade, not a misplaced history,
  // unless the frame lost the structure the history had, relit: a cut to a flat view darkens or brightens
  // every sample alike too. The same test on the blocks' structures (noise only adds to the frame's; the
  // history's bilinear taps only blur its own), where the history's, relit, is over the box's floor.
  const float frameStructure = float(noiseBins[kGainBase + 6]) / (kResidualSumScale * n);
  const float relitStructure = float(current) / float(history) * float(noiseBins[kGainBase + 7]) /
                               (kResidualSumScale * n);
  const bool structureLost = relitStructure * relitStructure >= kQuantVar * floorSlope2(historyMean) &&
                             relitStructure >= frameStructure * (1.0 + 4.0 * ratioStandardError);
  const bool fadeLike = abs(meanDifference) >= 0.5 * meanMagnitude;
  // Not on jittered input, whose point samples at an offset lose a sub-pixel wire's structure in some frames.
  const bool jittered = frameIsJittered();
  gPoseUnexplained = resets && changeAboveFloor && meanChange >= meanStep * (1.0 + 4.0 * ratioStandardError) &&
                     (!fadeLike || (structureLost && !jittered));
  return significant ? float(current) / float(history) : 1.0;
}
float gFrameGain = 1.0;

// Branch-free around texture reads, stores skipped past the edge (see PROCESS_BLOCK).
void processPixel(ivec2 p, ivec2 o) {
  ivec2 size = P.src0Size;
  const bool inRange = all(lessThan(p, size));
  const int mode = kMode;
  const bool neighbourhood = mode != kHmtaa;
  vec2 pc = vec2(p) + 0.5;
  vec3 cur = neighbourhood ? blockAt(o, 0, 0) : fetchSrc0(p);

  float invZ = P.fallbackInvZ;
  if ((kDepthBits & 1) != 0)
    invZ = invZFromDepth(texelFetch(uDepth0, P.depth0Offset + min(p, size - 1), 0).r, P.depth0);

  vec3 mn = vec3(0.0), var = vec3(0.0);  // taa: YCoCg; vtaa, hybrid: RGB
  vec3 ymn = vec3(0.0), yvar = vec3(0.0);  // hybrid: YCoCg moments for the history clip
  vec3 fc = vec3(0.0);                     // hybrid: the current frame through the footprint filter
  bool besideResolved = false;            // steady: item 15 (resolved_edge.glsl)
  if (neighbourhood) {
    const bool yCoCg = mode == kTaa || mode == kHybrid || mode == kSteady;
    vec3 s1, s2, sx;
    windowSums(o, yCoCg, s1, s2, sx);
    mn = s1 * (1.0 / 9.0);
    var = max(s2 * (1.0 / 9.0) - mn * mn, vec3(0.0));
    if (yCoCg) {  // YCoCg is linear: its moments follow from the RGB sums and cross products
      ymn = toYCoCg(mn);
      yvar = max(yCoCgSquares(s2, sx) * (1.0 / 9.0) - ymn * ymn, vec3(0.0));
    }
    if (mode == kTaa) {
      mn = ymn;
      var = yvar;
    }
    if (mode == kHybrid || mode == kSteady) {
      // [k, 1 - 2k, k]^2: centre, edge neighbours, corners (the rest of the 3x3 sum). Hybrid:
      // k = 1/16. Steady: k = steadyFootprint (Params::steadyFootprint, 1/24: the second moment
      // of the pixel's box footprint; 0 = off).
      const float k = mode == kHybrid ? 1.0 / 16.0 : P.steadyFootprint;
      vec3 edges = blockAt(o, -1, 0) + blockAt(o, 1, 0) + blockAt(o, 0, -1) + blockAt(o, 0, 1);
      vec3 sqrtEdges = vec3(0.0), sqrtCorners = vec3(0.0);
      if (mode == kSteady) {  // the same filter on square roots (Params::steadyFootprintEncoded)
        sqrtEdges = sqrt(blockAt(o, -1, 0)) + sqrt(blockAt(o, 1, 0)) +
                    sqrt(blockAt(o, 0, -1)) + sqrt(blockAt(o, 0, 1));
        sqrtCorners = sqrt(blockAt(o, -1, -1)) + sqrt(blockAt(o, 1, -1)) +
                      sqrt(blockAt(o, -1, 1)) + sqrt(blockAt(o, 1, 1));
      }
      fc = footprintEstimate(cur, edges, s1, sqrtEdges, sqrtCorners, k,
                             mode == kSteady && P.steadyFootprintEncoded > 0.5);
      if (mode == kSteady) {
        if (frameIsJittered()) {  // else the footprint above
          fc = jitteredFootprint(o, k);
          recentredClipMoments(o, ymn, yvar);
        } else if (kResolvedEdges && besideResolvedEdge(o, p, cur, invZ, size)) {
          besideResolved = true;  // item 15: the app's sample is the area average; no leak across its edge
          fc = cur;
        }
      }
    }
  }

  vec3 result = cur;
  float count = 1.0;  // the history's alpha: steady's sample count, 1 for the other modes
  const bool historyValid = P.historyValid != 0;
  vec2 shownFrom = vec2(0.0);  // steady: where the reprojection came from, for the held output
  vec3 estimateBefore = vec3(0.0);  // and last frame's estimate there (the history's tap)
  bool shownBefore = false;
  float shownHold = 0.0;
  if (mode == kSteady) {
    // Steady (README, method): the history reprojected through the exact previous render pose
    // (reproj[0]); clipped to the YCoCg box mean +- gamma*sigma of the current 3x3; blended with
    // alpha = max(1/(n+1), floor), n its sample count, divided by t^2 when the clip moved it t
    // sigma (t > 1), and alpha raised so that the resampling blur of the history stays bounded.
    vec2 q;
    float iz;
    const bool confirmed = reproject(P.reproj[0], pc, invZ, q, iz) && historyValid && !gPoseUnexplained;
    shownFrom = q;
    // Last frame's codes are of this frame's pixels only at the same render size; after a change of size
    // (an app's dynamic resolution) they are of other pixels, and the output rounds (round 39: holding them
    // across the change, its move measured in this frame's pixels, gave nothing at 1, 0.75).
    shownBefore = confirmed && P.shownValid != 0 && P.src1Size == P.src0Size;
    // The hold is for a picture that stood still: its margin shrinks with how far the picture moved at
    // this pixel since last frame, to nothing at half a pixel, where last frame's code is as likely a
    // neighbour's (a turn over a fine grating: codes of other places, kept).
    const vec2 moved = abs(q - pc);
    shownHold = P.steadyOutputHold * max(1.0 - 2.0 * max(moved.x, moved.y), 0.0);
    vec4 hs = sampleHistoryRgba(q);  // q is clamped into the image inside
    estimateBefore = hs.rgb;
    // Params::steadyClipCurvatureCentredGated (an option, off): the sign of the history's alpha is the
    // side of the current estimate its luma lay on last frame (negative: above). A history lagging
    // content that changes in place stays on one side; one averaging aliased detail flips at random.
    const bool sideGate = (kSteadyBoxSwitches & 4) != 0;
    const bool historyWasAbove = sideGate && hs.a < 0.0;
    hs.a = abs(hs.a);  // the count; where the tap mixed signs it reads lower (a safe direction)
    const vec3 historyYCoCg = toYCoCg(hs.rgb), estimateYCoCg = toYCoCg(fc);
    const bool historyAbove = historyYCoCg.x > estimateYCoCg.x;
    const bool lagsOneSide = !sideGate || historyAbove == historyWasAbove;
    vec3 boxCentre = ymn;
    vec3 clipExt2 = P.clipGamma * P.clipGamma * yvar;
    // Params::steadyClipCurvature (the default): the box no wider than kappa (|cxx| + |cyy|),
    // the largest offset of a reprojected static history from the 3x3 mean that is second order
    // in the signal; a lag (first order) beyond it is clipped, and rejected by the clip's t^2.
    // The 3x3's second differences along x and y in YCoCg: for the curvature box and item 12's trade.
    vec3 cxx = vec3(0.0), cyy = vec3(0.0);
    if (P.steadyClipCurvatureKappa > 0.0 || kBlurNoiseTrade) {
      const vec3 centre2 = 2.0 * blockAt(o, 0, 0);
      cxx = toYCoCg(blockAt(o, -1, 0) + blockAt(o, 1, 0) - centre2);
      cyy = toYCoCg(blockAt(o, 0, -1) + blockAt(o, 0, 1) - centre2);
    }
    if (P.steadyClipCurvatureKappa > 0.0) {
      const vec3 curvSum = abs(cxx) + abs(cyy);
      // Params::steadyClipCurvatureCentred (the default): per axis a static history lies
      // -s c'' from the 3x3 mean, s in [inner, kappa]: on one side. The box is that interval
      // (centre -(kappa + inner)/2 c'', half-width (kappa - inner)/2 |c''|) where it is narrower
      // than gamma sigma; elsewhere the gamma sigma box about the mean. With the gate, only where the
      // history lags on one side; elsewhere the symmetric box.
      if ((kSteadyBoxSwitches & 1) != 0 && lagsOneSide) {
        const float kappa = P.steadyClipCurvatureKappa, inner = P.steadyClipCurvatureInner;
        const vec3 halfWidth = 0.5 * (kappa - inner) * curvSum;
        const vec3 curvNarrower = step(halfWidth * halfWidth, clipExt2);  // 1 where the interval is
        boxCentre = ymn - curvNarrower * (0.5 * (kappa + inner)) * (cxx + cyy);
        clipExt2 = min(clipExt2, halfWidth * halfWidth);
      } else {  // round 6's box, symmetric about the mean
        const vec3 curvExt = P.steadyClipCurvatureKappa * curvSum;
        clipExt2 = min(clipExt2, curvExt * curvExt);
      }
    }
    // Params::steadyClipQuantSrgb (the default; the host sets the bit only for sRGB input): the floor
    // is half a step of the 8-bit input at the box mean's luma L, not in linear light. IEC 61966-2-1's
    // slope d(linear)/d(code) is (2.4 / 1.055) L^(7/12) above its toe; L^(5/8) bounds it from below
    // (0.79-1.0 of it over the codes), so the floor never reaches half a code and a history clipped
    // onto it still rounds to the input's own code. Never below the toe's 1/12.92. Squared: L^(5/4).
    clipExt2 += kQuantVar * floorSlope2(ymn.x);
    // Params::steadyNoiseEstimate: the box widened by one pixel's noise, so that a history may differ
    // from it by as much as the noisy render itself differs from the truth (i.i.d. noise s2 per RGB
    // channel is 3/8, 1/2, 3/8 s2 per YCoCg channel). Three of the centre's standard deviations
    // (the three-sigma rule) let a fade's lag through at up to 3x none's error.
    if (kNoiseAware) clipExt2 += P.steadyNoiseVariance * vec3(0.375, 0.5, 0.375);
    // Params::steadyClipHoldsCurrent (not the default): the box reaches out, on the history's side
    // and per channel, to the current frame's own estimate of the pixel's area average (fc).
    const vec3 toCur = estimateYCoCg - boxCentre;
    const vec3 holdsCurrent2 = toCur * toCur * P.steadyClipHoldsCurrent;
    const vec3 boxExt2 = clipExt2;  // before the reach, which depends on the history's side
    vec3 d = historyYCoCg - boxCentre;
    clipExt2 = max(boxExt2, step(vec3(0.0), d * toCur) * holdsCurrent2);
    vec3 t2v = d * d / clipExt2;
    float t2 = max(t2v.x, max(t2v.y, t2v.z));
    const float asWasT2 = t2;  // the evidence against the count (below)
    // Params::steadyGainCompensation (round 16): where the frame changed as a whole (a fade, an
    // exposure change) the history times the frame's gain is a second candidate (FSR2's pre-exposure,
    // estimated). It is taken only where the box rejects the history as it was, the relit one lies
    // inside the box (the pixel's own content, relit) and nearer this frame's estimate fc (per channel in
    // units of the box's extent): a sub-code fade over a flat 3x3 no longer clips onto the floor. A
    // history the box admits keeps its value, so a gain that drifts by a few tenths of a percent (a
    // video's zoom) cannot bias it pixel by pixel; a still surround beside changing content keeps its
    // own. The evidence against the count stays the history's own (asWasT2): a relit history is a
    // hypothesis the box admits, not a confirmation. Round 17: where the gain explains the frame's change
    // (gGainExplains) also where the box admits the history: a fade's lag inside a wide box; a video's
    // drifting gain explains none of its change.
    if (kGainCompensated && gFrameGain != 1.0) {  // uniform: no gain found, nothing to do
      const vec3 relit = historyYCoCg * gFrameGain;
      const vec3 relitD = relit - boxCentre;
      const vec3 relitExt2 = max(boxExt2, step(vec3(0.0), relitD * toCur) * holdsCurrent2);
      const vec3 relitT2v = relitD * relitD / relitExt2;
      const float relitT2 = max(relitT2v.x, max(relitT2v.y, relitT2v.z));
      const vec3 asWas = historyYCoCg - estimateYCoCg, scaled = relit - estimateYCoCg;
      const bool nearer = dot(scaled * scaled / boxExt2, vec3(1.0)) < dot(asWas * asWas / boxExt2, vec3(1.0));
      const bool takeRelit = (t2 > 1.0 || gGainExplains) && relitT2 <= 1.0 && nearer;
      d = takeRelit ? relitD : d;
      clipExt2 = takeRelit ? relitExt2 : clipExt2;
      t2 = takeRelit ? relitT2 : t2;
    }
    vec3 h = t2 > 1.0 ? boxCentre + d * inversesqrt(t2) : boxCentre + d;
    const float cap = 1.0 / P.steadyAlphaFloor;
    float n = confirmed ? clamp(kHistoryEncoding != 0 ? hs.a * cap : hs.a, 0.0, cap) : 0.0;  // storeHistory
    n *= asWasT2 > 1.0 ? mix(1.0, 1.0 / asWasT2, P.steadyClipRejects) : 1.0;
    float a = max(1.0 / (n + 1.0), P.steadyAlphaFloor);
    vec2 f = fract(q - 0.5);                // bilinear tap offset within the texel
    // The tap's blur variance per axis in this frame's px^2: a history texel spans src0Size / src1Size of
    // them (an app's dynamic resolution, round 37; exactly 1 at a fixed size).
    const vec2 span = P.src1Size == P.src0Size ? vec2(1.0) : vec2(P.src0Size) / vec2(P.src1Size);
    vec2 axisBlur = f * (1.0 - f) * (span * span);
    // The added blur variance over the budget (the box's x + y variance): per axis, the blurrier
    // axis counted for both (Params::steadyHistoryBlurPerAxis); else summed over the axes.
    float v = P.steadyHistoryBlurPerAxis > 0.5 ? 2.0 * max(axisBlur.x, axisBlur.y) : axisBlur.x + axisBlur.y;
    float blur = v * P.steadyInvBlurBudgetPx2;
    float guardAlpha = blur / (blur + 1.0);  // steady-state blur (1 - a) / a * v <= budget
    // Params::steadyBlurNoiseTrade (round 26): in a noisy render, per axis, the alpha that minimises the
    // exponential mean's noise plus its blur's bias on the luma's curvature; never above the guard's.
    const float noiseLuma2 = 0.375 * P.steadyNoiseVariance;  // (R + 2G + B) / 4 of i.i.d. RGB noise
    if (kBlurNoiseTrade && noiseLuma2 > 0.0) {
      const vec2 curvature = vec2(cxx.x, cyy.x);  // the luma's
      const vec2 signalCurvature = sqrt(max(curvature * curvature - 6.0 * noiseLuma2, vec2(0.0)));
      vec2 tradeAlpha = pow(axisBlur * signalCurvature * inversesqrt(noiseLuma2), vec2(2.0 / 3.0));
      tradeAlpha = max(tradeAlpha, axisBlur / (axisBlur + 0.25));  // the blur's 2 sigma within the 3x3
      const vec2 axisGuard = 2.0 * axisBlur * P.steadyInvBlurBudgetPx2;
      const vec2 axisAlpha = min(axisGuard / (axisGuard + 1.0), tradeAlpha);
      guardAlpha = max(axisAlpha.x, axisAlpha.y);
    }
    a = max(a, guardAlpha);
    if (besideResolved) {
      // Item 15: no blur budget beside an edge the app resolved, but for 1e-4 px^2 (a tap moved by float
      // rounding of a still picture's reprojection keeps its history).
      const float resolvedBlur = 2.0 * max(axisBlur.x, axisBlur.y) * 1e4;
      a = max(a, resolvedBlur / (resolvedBlur + 1.0));
    }
    a = P.steadyConfidence > 0.5 ? a : P.taaAlpha;  // ablation: constant alpha
    a = confirmed ? a : 1.0;
    cur = fc;
    // Select, not mix, when unconfirmed: a never-written history may hold NaN (and max(NaN, 0) is 0).
    result = confirmed ? max(fromYCoCg(mix(h, toYCoCg(cur), a)), vec3(0.0)) : cur;
    count = min(1.0 / a, cap);  // the samples the blend holds: n + 1, fewer where alpha was raised
    count = sideGate && confirmed && historyAbove ? -count : count;  // this frame's side, for the next
  } else if (mode == kTaa) {
    vec2 q;
    float iz;
    bool inside = reproject(P.reproj[0], pc, invZ, q, iz);
    // Variance clipping (seed 001 §4.4): clip the history towards the mean onto the box
    // mean +- gamma*sigma, then blend with the constant weight taaAlpha.
    vec3 h = clipToBox(toYCoCg(sampleHistory(q)), mn, P.clipGamma * P.clipGamma * var + 1e-12);
    vec3 blended = max(mix(fromYCoCg(h), cur, P.taaAlpha), vec3(0.0));
    result = historyValid && inside ? blended : cur;
  } else {
    vec3 past;
    bool hasPast = pastColour(pc, invZ, past) && historyValid;
    float a;
    if (mode == kVtaa) {
      a = varianceAlpha(past, mn, var);
    } else if (mode == kHmtaa) {
      // Seed 003 Eq. 5 then Eq. 4 with the localised w'_min (shape S computed on the CPU).
      vec3 dc = cur - past;
      float cdiff = clamp(sqrt(dot(dc, dc) * (1.0 / 3.0)), 0.0, 1.0);
      float wmin = P.wMin - (P.wMin - P.wLowerBound) * cdiff;
      a = P.shapeS >= 1.0 ? 1.0 : P.shapeS * (1.0 - wmin) + wmin;  // h > h_max: the current frame
    } else {
      // Hybrid. (1) taa's variance clipping of the history to the YCoCg box mean +- gamma*sigma
      // of the current 3x3 (gamma = taaClipGamma): stops ghosting of moving objects and
      // disocclusions. (2) The variance weight of seed 002 Eq. 4 for the clipped history, never
      // below A(h) of seed 003 Eq. 4 with w_min = alphaMin. (3) The current frame enters through
      // a [1/16, 7/8, 1/16]^2 footprint filter: the target is the pixel-area average and a lone
      // centre sample is sharper than that (measured: lower RMSE on thin/high-contrast detail).
      vec3 clipExt2 = P.clipGamma * P.clipGamma * yvar + 1e-12;
      past = max(fromYCoCg(clipToBox(toYCoCg(past), ymn, clipExt2)), vec3(0.0));
      float ah = P.shapeS * (1.0 - P.alphaMin) + P.alphaMin;
      a = P.shapeS >= 1.0 ? 1.0 : max(varianceAlpha(past, mn, var), ah);  // h > h_max: current frame
      cur = a < 1.0 ? fc : cur;
    }
    // Seed 003 Eq. 3 (and seed 002's lerp(X, Y, alpha)): a is the weight of the current frame.
    result = hasPast ? (a >= 1.0 ? cur : mix(past, cur, a)) : result;
  }
  if (any(isnan(result)) || any(isinf(result))) {
    result = cur;
    count = 1.0;
  }
  result = clamp(result, vec3(0.0), vec3(65000.0));  // stays finite in half precision
  if (inRange) {
    // The history's alpha is steady's sample count; the output's alpha is the app's (alphaOf).
    if (kWriteHist) storeHistory(p, result, count, P.steadyAlphaFloor);  // 8-bit: steady's count / its cap
    // Round 20 (Params::steadyOutputHold): the 8-bit output keeps last frame's code (storeHeldOutput).
    bool outputHeld = kMode == 4 && (kSteadyBoxSwitches & 512) != 0;  // not const: see main
    const float outAlpha = kWriteOut ? (neighbourhood ? blockAlphaOf(p, o) : alphaOf(p)) : 1.0;
    if (kWriteOut && outputHeld)
      storeHeldOutput(p, result, outAlpha, shownBefore, shownFrom, estimateBefore, shownHold);
    if (kWriteOut && !outputHeld) storeOutput(p, vec4(result, outAlpha));
  }
}

void main() {
  ivec2 base = ivec2(gl_GlobalInvocationID.xy) * ivec2(kBlockW, kBlockH);
  // The switches spelled out: glslang leaves a spec constant's expression undefined when main is its first use.
  if (kMode == 4 && (kSteadyBoxSwitches & 128) != 0) {  // the probe: by regions of 4x4 blocks on every device
    probeFrame(ivec2(gl_GlobalInvocationID.xy));
    return;
  }
  if (kMode == 4 && (kSteadyBoxSwitches & 64) != 0) gFrameGain = frameGain();
  if (any(greaterThanEqual(base, P.src0Size))) return;
  if (kMode != kHmtaa) loadBlock(base, kMode == kTaa || kMode == kHybrid || kMode == kSteady);
  PROCESS_BLOCK(base);
}
