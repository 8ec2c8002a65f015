// steady's probe (temporal.comp's mode 4 with bit 7, its own dispatch before the passes): one invocation per
// block of P.probeBlockPx, whose sums the temporal passes of the same frame read (frameGain) and the host after
// it (noise_estimate.h). Included by temporal.comp after the helpers it shares with the pass.

// The probe's 5x5 of src0 around p, row by row (clamped into the image by fetchSrc0): its footprint
// estimate reads the 3x3 inside it and the residual's detail all of it, each texel fetched once (the
// residual's rows fetched 45 before round 32, and the 3x3 nine more).
const int kProbeWindowSide = 5;
vec3 probeWindowAt(const vec3 window[25], int x, int y) { return window[(y + 2) * kProbeWindowSide + x + 2]; }
void loadProbeWindow(ivec2 p, out vec3 window[25]) {
  [[unroll]] for (int y = -2; y <= 2; ++y)
    [[unroll]] for (int x = -2; x <= 2; ++x) window[(y + 2) * kProbeWindowSide + x + 2] = fetchSrc0(p + ivec2(x, y));
}
// The probe's 3x3 of src0 around p (inside the image): steady's footprint estimate of the pixel, its
// centre texel, and round 13's detail, the luma's x^2 y^2 contrast (weights (1, -2, 1) x (1, -2, 1),
// norm 6) scaled to the noise's standard deviation. Sums in the pass's order (windowSums: by columns).
vec3 probeFootprint(const vec3 window[25], out vec3 centre, out float detail) {
  vec3 c[9];
  [[unroll]] for (int y = -1; y <= 1; ++y)
    [[unroll]] for (int x = -1; x <= 1; ++x) c[(y + 1) * 3 + x + 1] = probeWindowAt(window, x, y);
  const vec3 corners = c[0] + c[2] + c[6] + c[8];
  detail = abs(toYCoCg(corners - 2.0 * (c[1] + c[3] + c[5] + c[7]) + 4.0 * c[4]).x) * (1.0 / 6.0);
  const vec3 edges = c[3] + c[5] + c[1] + c[7];  // (-1, 0), (1, 0), (0, -1), (0, 1)
  const vec3 sum3x3 = (c[0] + c[3] + c[6]) + (c[1] + c[4] + c[7]) + (c[2] + c[5] + c[8]);
  const vec3 sqrtEdges = sqrt(c[3]) + sqrt(c[5]) + sqrt(c[1]) + sqrt(c[7]);
  const vec3 sqrtCorners = sqrt(c[0]) + sqrt(c[2]) + sqrt(c[6]) + sqrt(c[8]);
  centre = c[4];
  return footprintEstimate(c[4], edges, sum3x3, sqrtEdges, sqrtCorners, P.steadyFootprint,
                           P.steadyFootprintEncoded > 0.5);
}
// Round 14: the same contrast of the residual between this frame's footprint estimate (steady's fc,
// unjittered) and the history reprojected to q, over the 3x3 around the pixel: what changed since the
// last frame at the finest scale (noise, every frame) and not the picture's own fine detail (aliasing
// under a still head, which the history holds too). Its own histogram; the host takes the smaller of
// the two estimates (noise_estimate.h).
float residualDetail(const vec3 window[25], vec2 q) {
  const float k = P.steadyFootprint;
  const bool encoded = P.steadyFootprintEncoded > 0.5;
  const vec3 w = vec3(k, 1.0 - 2.0 * k, k);
  vec3 texelsEncoded[25];
  [[unroll]] for (int i = 0; i < 25; ++i) texelsEncoded[i] = encoded ? sqrt(window[i]) : window[i];
  vec3 rows[15];  // the 5x5 filtered along x: rows y = -2..2, columns x = -1..1
  [[unroll]] for (int y = -2; y <= 2; ++y)
    [[unroll]] for (int x = -1; x <= 1; ++x) {
      vec3 s = vec3(0.0);
      [[unroll]] for (int i = -1; i <= 1; ++i) s += w[i + 1] * probeWindowAt(texelsEncoded, x + i, y);
      rows[(y + 2) * 3 + x + 1] = s;
    }
  const vec2 pos = q - 0.5;  // texel centres at integers
  const ivec2 t = ivec2(floor(pos));
  const vec2 f = pos - vec2(t);
  vec3 texels[16];  // texels t + (-1..2, -1..2): the bilinear taps at q + (-1..1, -1..1)
  [[unroll]] for (int j = 0; j < 4; ++j)
    [[unroll]] for (int i = 0; i < 4; ++i) texels[j * 4 + i] = historyTexel(t + ivec2(i - 1, j - 1));
  const vec3 weight1d = vec3(1.0, -2.0, 1.0);
  float detail = 0.0;
  [[unroll]] for (int y = -1; y <= 1; ++y)
    [[unroll]] for (int x = -1; x <= 1; ++x) {
      vec3 s = vec3(0.0);
      [[unroll]] for (int j = -1; j <= 1; ++j) s += w[j + 1] * rows[(y + j + 2) * 3 + x + 1];
      const vec3 estimate = encoded ? s * s : s;
      const int i0 = (y + 1) * 4 + x + 1;
      const vec3 history = mix(mix(texels[i0], texels[i0 + 1], f.x), mix(texels[i0 + 4], texels[i0 + 5], f.x), f.y);
      detail += weight1d[x + 1] * weight1d[y + 1] * toYCoCg(estimate - history).x;
    }
  return abs(detail) * (1.0 / 6.0);
}
// Round 15: the residual's luma at the pixel itself, summed over the frame with its magnitude (fixed
// point, 2^-11; clamped to +-1/2, a change beyond doubt, so that 2^21 samples, two eyes of 4096^2,
// cannot overflow). Noise's residual averages out over a frame; a picture that changes as a whole (a
// fade) leaves a mean, and the host then drops the noise allowance (noise_estimate.h, residualMeanSide).
const float kResidualSumScale = 2048.0;
int residualSumUnits(float residual) {
  return abs(residual) <= 1e30 ? int(round(clamp(residual, -0.5, 0.5) * kResidualSumScale)) : 0;  // NaN, inf: 0
}

// Round 13: one sample of the frame's contrast histogram (bin 0 below 2^kNoiseLowestLog2, then quarter
// octaves); the host takes its median (noise_estimate.h).
void addNoiseSample(float absDetail, int histogram) {
  if (!(absDetail >= 0.0)) return;  // NaN
  const float octaves = log2(max(absDetail, 1e-30)) - kNoiseLowestLog2;
  const int bin = octaves < 0.0 ? 0 : min(int(kNoiseBinsPerOctave * octaves) + 1, kNoiseBins - 1);
  atomicAdd(noiseBins[noiseCopyBase() + histogram * kNoiseBins + bin], 1u);
}
// The frame's probe: one invocation per block of P.probeBlockPx (4 px up to 2^14 blocks an eye, round 17;
// filter_passes.h), sampled at the block's centre, both eyes.
// - Rounds 13-15 (bits 4, 5): the noise records, into the copy of the invocation's workgroup: the frame's
//   contrast (off the image's edge: the 3x3 is all real); where the history is reprojected, the
//   residual's contrast (2 px off the edge: its 5x5) and its luma at the pixel (residualSumUnits).
//   Jittered input: the residual would hold the jitter's own sample differences; none then.
// - Round 16 (bit 6): the gain's record: the luma of this frame and of the history reprojected through the
//   previous pose, summed (in [0, 1], units 2^-10: 2^21 samples cannot overflow), the magnitude of their
//   difference (units as the residual's) and the samples.
// The sums are added up in the workgroup first and added to the records once per workgroup (integer
// sums: the same in any order; few adds to the same words, which a GPU's atomics serialise).
// - Round 31 (bit 11): at the same samples, the luma's mean over a block of 4x4 pixels in this frame and in
//   the history reprojected to it: the magnitude of their difference, and of the difference between the
//   frame's block and its neighbour a block to the right (samples whose i + j is even) or below (odd; round
//   32: one neighbour a sample, where round 31 averaged both). Words 4 and 5 of the record.
// - Round 33 (bit 11): the structure of the frame's block and of the history's (blockStructure), words 6 and 7.
// - Round 42 (bit 13, P.headLockedStep): the head-locked switch's testimonies (observeHeadLocked), counted into
//   word 8; compiled in only where an epoch's frame asks for them.
shared uint sProbeSums[11];  // the gain's four sums, the residual's two, the blocks' two (round 31), structures,
                             // the head-locked switch's steady samples (round 42)
const int kProbeSumsGain = 0, kProbeSumsResidual = 4, kProbeSumsBlocks = 6, kProbeSumsStructure = 8;
const int kProbeSumsHeadLocked = 10;
// Round 31: the luma's mean over the 4x4 texels of src0 around the texel corner `corner` (centres corner
// +- 0.5, +- 1.5), and the history's over the same area around q: four bilinear taps at texel corners, each
// the mean of a 2x2 quad (a quad's corner kept a texel inside the image: its texels are the eye's own).
// The sample's own block is in its 5x5 window (round 32: summed from the texels fetched there).
float frameQuadLuma(vec2 corner) {
  const vec3 c = tapSrc0(clamp(corner, vec2(1.0), vec2(P.src0Size) - 1.0)).rgb;
  return toYCoCg((kCleanSrc & 1) != 0 ? c : sanitize(c)).x;
}
float frameBlockLuma(ivec2 corner) {
  const vec2 c = vec2(corner);
  return 0.25 * (frameQuadLuma(c + vec2(-1.0, -1.0)) + frameQuadLuma(c + vec2(1.0, -1.0)) +
                 frameQuadLuma(c + vec2(-1.0, 1.0)) + frameQuadLuma(c + vec2(1.0, 1.0)));
}
// The block of texels -1 .. 2 of the window (edge texels repeated), and its four 2x2 quads (top left, top
// right, bottom left, bottom right).
float windowBlockLuma(const vec3 window[25], out vec4 quads) {
  float luma[16];
  float sum = 0.0;
  [[unroll]] for (int y = -1; y <= 2; ++y)
    [[unroll]] for (int x = -1; x <= 2; ++x) {
      luma[(y + 1) * 4 + x + 1] = toYCoCg(probeWindowAt(window, x, y)).x;
      sum += luma[(y + 1) * 4 + x + 1];
    }
  quads = 0.25 * vec4(luma[0] + luma[1] + luma[4] + luma[5], luma[2] + luma[3] + luma[6] + luma[7],
                      luma[8] + luma[9] + luma[12] + luma[13], luma[10] + luma[11] + luma[14] + luma[15]);
  return sum * (1.0 / 16.0);
}
// The history's block around q, and its four taps in the quads' order.
float historyBlockLuma(vec2 q, out vec4 taps) {
  taps = vec4(toYCoCg(sampleHistory(q + vec2(-1.0, -1.0))).x, toYCoCg(sampleHistory(q + vec2(1.0, -1.0))).x,
              toYCoCg(sampleHistory(q + vec2(-1.0, 1.0))).x, toYCoCg(sampleHistory(q + vec2(1.0, 1.0))).x);
  return 0.25 * (taps.x + taps.y + taps.z + taps.w);
}
// Round 33: a block's structure, the mean of its left-right and top-bottom differences between halves, from
// its quads. A fade keeps it, times the gain; a cut to a flat view loses it.
float blockStructure(vec4 quads) {
  return 0.25 * (abs(quads.x + quads.z - quads.y - quads.w) + abs(quads.x + quads.y - quads.z - quads.w));
}
// Round 42: the head-locked switch (Params::steadyHeadLockedSwitch; layer/core/src/filter_head_locked.h has the
// epochs and the decision). The probe writes no history: binding 4 holds the eye's record in its dispatch, one
// texel a sample: the reference's block luma in two half floats (its nearest half in r, the rest in a: a
// half alone is off by up to an eighth of a code, too much beside a match of one), 1 + the sample's head-locked
// testimonies in g (0: no reference yet), its world testimonies in b. Luma as displayed (the app's codes over
// 255: an sRGB input encoded again), the scale of round 41's thresholds.
layout(set = 0, binding = 4, rgba16f) uniform image2D uHeadLockedRecord;
const int kHeadLockedTestify = 2;  // filter_head_locked.h, HeadLockedStep (1: take the reference only)
const float kHeadLockedShiftPx = 2.0;        // filter_head_locked.h
const float kHeadLockedEpochsToDecide = 2.0;  // filter_head_locked.h, kHeadLockedEvidenceSamples's epochs
const float kHeadLockedMostTestimonies = 1000.0;  // exact in half floats
float displayedLuma(vec3 c) {
  c = clamp(c, 0.0, 1.0);
  return toYCoCg(P.headLockedInputDecoded > 0.5 ? linearToSrgb(c) : c).x;
}
// The displayed luma's mean over the 4x4 texels -2 .. 1 of the window: the block whose centre is the sample's
// top-left corner (texel corners at integers), round 41's block at a sample.
float windowDisplayedBlock(const vec3 window[25]) {
  float sum = 0.0;
  [[unroll]] for (int y = -2; y <= 1; ++y)
    [[unroll]] for (int x = -2; x <= 1; ++x) sum += displayedLuma(probeWindowAt(window, x, y));
  return sum * (1.0 / 16.0);
}
// The block mean at a point between texel corners: the blocks at the four corners around it, bilinear, which
// weighs the 5x5 texels from floor(q) - 2 by (1 - f, 1, 1, 1, f) per axis.
float displayedBlockAt(vec2 q) {
  const ivec2 t = ivec2(floor(q));
  const vec2 f = q - vec2(t);
  float sum = 0.0;
  [[unroll]] for (int y = -2; y <= 2; ++y) {
    const float wy = y == -2 ? 1.0 - f.y : y == 2 ? f.y : 1.0;
    [[unroll]] for (int x = -2; x <= 2; ++x) {
      const float wx = x == -2 ? 1.0 - f.x : x == 2 ? f.x : 1.0;
      sum += wx * wy * displayedLuma(fetchSrc0(t + ivec2(x, y)));
    }
  }
  return sum * (1.0 / 16.0);
}
// A block's 16 texels inside the eye.
bool blockInside(vec2 corner) {
  return all(greaterThanEqual(corner, vec2(2.0))) && all(lessThanEqual(corner, vec2(P.src0Size) - 2.0));
}
// Two block means that show the same thing differ by what can change a pixel between them: the frame's own
// finest detail (round 13's estimate from the probe's histogram: noise, and aliasing, whose pixels change
// under a sub-pixel move), a pixel's luma's standard deviation (3/8 of a channel's variance,
// noise_estimate.h) through the display encoding's slope at the block's level, times sqrt(2) / 4 (16
// texels each). Three of those, and never less than a code, is a match (round 41, whose study took the same
// detail from the frame itself).
float headLockedMatch(float displayedLevel) {
  float slope = 1.0;
  if (P.headLockedInputDecoded > 0.5) {  // d(encoded)/d(linear) at the displayed level
    const float linearLevel = pow((max(displayedLevel, 0.0) + 0.055) / 1.055, 2.4);
    slope = linearLevel <= 0.0031308 ? 12.92 : (1.055 / 2.4) * pow(linearLevel, 1.0 / 2.4 - 1.0);
  }
  const float noise = sqrt(max(P.headLockedDetailVariance, 0.0) * 0.375) * slope * (sqrt(2.0) / 4.0);
  return max(1.0 / 255.0, 3.0 * noise);
}
// The sample at pixel p: its block now, against the record's reference (in an epoch's last frame), then the
// record holds it. Head-locked content stays at its pixel; the world moved by d to where the head's rotation
// carried it (P.reproj[1]: the reference's pixel -> this frame's). A sample testifies only where it has moved
// kHeadLockedShiftPx and the two hypotheses predict different blocks for it now: the reference's block at p
// (head-locked) and at p - d (the world's; round 41 read it in the reference frame). The record keeps the
// reference at the samples only, so this frame stands in for it: at p + d the world has carried the
// reference's p, at p - d head-locked content shows the reference's p - d. Both must differ from the block
// at p by a mismatch (a near-flat picture, aliasing's slow moire, a flat patch beside an edge the rotation
// does not explain: no evidence). It counts once it testified head-locked in two epochs and never for the
// world. Round 43: content drawn without filtering (a texture's nearest texel, unresolved geometry) moves in
// whole pixels: an edge across a move of d shows moved by floor(d) or ceil(d) on each axis, and under a move
// of less than a pixel across it stays put, as a HUD would (held-out text under a nod decided so). So the
// world's prediction is also the block at each of the four roundings of d, and a sample testifies only where
// every prediction differs from the head-locked one.
void observeHeadLocked(ivec2 sampleIndex, ivec2 p, const vec3 window[25], bool jittered) {
  const vec2 here = vec2(p);
  if (!blockInside(here)) return;
  const float now = windowDisplayedBlock(window);
  if (isnan(now)) return;
  float headLocked = 0.0, world = 0.0;
  if (P.headLockedStep == kHeadLockedTestify) {
    const vec4 record = imageLoad(uHeadLockedRecord, sampleIndex);
    headLocked = max(record.g - 1.0, 0.0);
    world = record.b;
    const vec4 carriedTo = P.reproj[1] * vec4(here, 1.0, 0.0);
    if (record.g > 0.5 && !jittered && carriedTo.z > 1e-12) {
      const vec2 there = carriedTo.xy / carriedTo.z;
      const vec2 mirrored = 2.0 * here - there;
      if (distance(there, here) >= kHeadLockedShiftPx && blockInside(there) && blockInside(mirrored)) {
        const float carried = displayedBlockAt(there), before = record.r + record.a;
        const float match = headLockedMatch(before), mismatch = 4.0 * match;
        bool distinct = abs(now - carried) > mismatch && abs(now - displayedBlockAt(mirrored)) > mismatch;
        float worldResidual = abs(carried - before);
        const vec2 move = there - here;
        for (int rounding = 0; rounding < 4 && distinct; ++rounding) {
          const ivec2 wholeMove = ivec2((rounding & 1) != 0 ? ceil(move.x) : floor(move.x),
                                        (rounding & 2) != 0 ? ceil(move.y) : floor(move.y));
          if (!blockInside(vec2(p + wholeMove)) || !blockInside(vec2(p - wholeMove))) {
            distinct = false;
            break;
          }
          // At a texel corner displayedBlockAt weighs its fifth row and column by 0: the 4x4 block there.
          const float carriedWhole = displayedBlockAt(vec2(p + wholeMove));
          distinct = abs(now - carriedWhole) > mismatch && abs(now - displayedBlockAt(vec2(p - wholeMove))) > mismatch;
          worldResidual = min(worldResidual, abs(carriedWhole - before));
        }
        if (distinct) {
          const float headLockedResidual = abs(now - before);
          if (headLockedResidual <= match && worldResidual > mismatch)
            headLocked = min(headLocked + 1.0, kHeadLockedMostTestimonies);
          if (worldResidual <= match && headLockedResidual > mismatch)
            world = min(world + 1.0, kHeadLockedMostTestimonies);
        }
      }
    }
    if (headLocked >= kHeadLockedEpochsToDecide && world == 0.0) atomicAdd(sProbeSums[kProbeSumsHeadLocked], 1u);
  }
  const float nowHalf = unpackHalf2x16(packHalf2x16(vec2(now, 0.0))).x;
  imageStore(uHeadLockedRecord, sampleIndex, vec4(nowHalf, headLocked + 1.0, world, now - nowHalf));
}
void probeFrame(ivec2 sampleIndex) {
  const ivec2 p = sampleIndex * P.probeBlockPx + P.probeBlockPx / 2;
  // The switches spelled out (bits 4, 5, 6, 11), as in main: glslang defines a spec constant's expression with
  // && where it is first used, and a later use in a block that does not follow it is invalid SPIR-V.
  const bool noiseSampled = (kSteadyBoxSwitches & 16) != 0, residualSampled = (kSteadyBoxSwitches & 32) != 0;
  const bool probesGain = (kSteadyBoxSwitches & 64) != 0, blocksProbed = (kSteadyBoxSwitches & 2048) != 0;
  const bool headLockedObserved = (kSteadyBoxSwitches & 8192) != 0;  // round 42: an epoch's frame
  const bool jittered = frameIsJittered();
  const bool leader = gl_LocalInvocationIndex == 0u;
  if (leader)
    for (int i = 0; i < 11; ++i) sProbeSums[i] = 0u;
  barrier();
  if (all(lessThan(p, P.src0Size))) {
    vec3 centre;
    float frameDetail;
    vec3 window[25];
    loadProbeWindow(p, window);
    const vec3 estimate = probeFootprint(window, centre, frameDetail);
    if (noiseSampled && all(lessThan(p + 1, P.src0Size))) addNoiseSample(frameDetail, 0);
    if (headLockedObserved) observeHeadLocked(sampleIndex, p, window, jittered);
    float invZ = P.fallbackInvZ;
    if ((kDepthBits & 1) != 0) invZ = invZFromDepth(texelFetch(uDepth0, P.depth0Offset + p, 0).r, P.depth0);
    vec2 q;
    float iz;
    // The uniform last: lavapipe (Mesa 22.3) folds a branch on uniforms alone into a pipeline at its first
    // dispatch, and where that removed half its code it compiles the pipeline again at every later dispatch. The
    // head-locked switch's probe first runs in a frame without a history, and was compiled again in every frame
    // after (round 49: 6 ms a frame from Mesa's shader cache, 280 ms without one).
    const bool insideHistory = reproject(P.reproj[0], vec2(p) + 0.5, invZ, q, iz);
    if (insideHistory && P.historyValid != 0) {
      const vec3 reprojected = sampleHistory(q);
      if (residualSampled && !jittered && all(lessThan(p + 2, P.src0Size))) {
        addNoiseSample(residualDetail(window, q), 1);
        const int units = residualSumUnits(toYCoCg(estimate - reprojected).x);
        atomicAdd(sProbeSums[kProbeSumsResidual], uint(units));  // two's complement: a signed sum
        atomicAdd(sProbeSums[kProbeSumsResidual + 1], uint(abs(units)));
      }
      const float currentLuma = clamp(toYCoCg(centre).x, 0.0, 1.0);
      const float historyLuma = clamp(toYCoCg(reprojected).x, 0.0, 1.0);
      if (probesGain && !isnan(currentLuma) && !isnan(historyLuma)) {
        atomicAdd(sProbeSums[kProbeSumsGain], uint(round(currentLuma * kLumaSumScale)));
        atomicAdd(sProbeSums[kProbeSumsGain + 1], uint(round(historyLuma * kLumaSumScale)));
        atomicAdd(sProbeSums[kProbeSumsGain + 2],
                  uint(round(min(abs(currentLuma - historyLuma), 0.5) * kResidualSumScale)));
        atomicAdd(sProbeSums[kProbeSumsGain + 3], 1u);
        if (blocksProbed) {  // p + 1: the block's centre is the pixel's lower right corner, q + 0.5 in the history
          vec4 quads, quadsBefore;
          const float block = windowBlockLuma(window, quads), blockBefore = historyBlockLuma(q + 0.5, quadsBefore);
          const bool stepAcross = ((sampleIndex.x + sampleIndex.y) & 1) == 0;  // half the taps; the same mean
          const float blockStep = abs(frameBlockLuma(p + (stepAcross ? ivec2(5, 1) : ivec2(1, 5))) - block);
          const float blockChange = isnan(blockBefore) ? 0.0 : abs(block - blockBefore);
          atomicAdd(sProbeSums[kProbeSumsBlocks], uint(round(min(blockChange, 0.5) * kResidualSumScale)));
          atomicAdd(sProbeSums[kProbeSumsBlocks + 1], uint(round(min(blockStep, 0.5) * kResidualSumScale)));
          if (!isnan(blockBefore)) {
            const float structure = blockStructure(quads), structureBefore = blockStructure(quadsBefore);
            atomicAdd(sProbeSums[kProbeSumsStructure], uint(round(min(structure, 0.5) * kResidualSumScale)));
            atomicAdd(sProbeSums[kProbeSumsStructure + 1], uint(round(min(structureBefore, 0.5) * kResidualSumScale)));
          }
        }
      }
    }
  }
  barrier();
  if (!leader) return;
  const uint residualSums = noiseCopyBase() + kNoiseHistograms * kNoiseBins;
  if (residualSampled && sProbeSums[kProbeSumsResidual + 1] != 0u) {
    atomicAdd(noiseBins[residualSums], sProbeSums[kProbeSumsResidual]);
    atomicAdd(noiseBins[residualSums + 1], sProbeSums[kProbeSumsResidual + 1]);
  }
  if (sProbeSums[kProbeSumsHeadLocked] != 0u) atomicAdd(noiseBins[kGainBase + 8], sProbeSums[kProbeSumsHeadLocked]);
  if (probesGain && sProbeSums[kProbeSumsGain + 3] != 0u) {
    for (int i = 0; i < 4; ++i) atomicAdd(noiseBins[kGainBase + i], sProbeSums[kProbeSumsGain + i]);
    if (blocksProbed)
      for (int i = 0; i < 4; ++i) atomicAdd(noiseBins[kGainBase + 4 + i], sProbeSums[kProbeSumsBlocks + i]);
  }
}
