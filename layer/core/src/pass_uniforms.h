// The uniform block of every filter pass (PassParams in shaders/common.glsl), member by member.
#pragma once

#include <cstddef>
#include <cstdint>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

namespace steadyxr::core {

// Normalised depth n -> 1/z: 1/z = invNear + n * invFarMinusInvNear, n = (d - minDepth) *
// invDepthRange (1/z is linear in the stored depth; farZ may be +inf, then 1/farZ = 0).
struct alignas(16) DepthToInvZ {  // std140: a struct member starts on 16 bytes
  float invNear;
  float invFarMinusInvNear;
  float minDepth;
  float invDepthRange;
};

// Mirrors PassParams in shaders/common.glsl, std140: scalars on 4 bytes, vec2/ivec2 on 8, vec4,
// mat4 and structs on 16 (the offsets are checked below). A pass ignores the members it does not
// need. The per-pipeline switches (mode, sample count, write flags, depth bits) are not here: they
// are specialisation constants (SpecKey in filter.cpp, constant_id in common.glsl).
struct PassUniforms {
  // Pixel centre (x, y, 1, 1/z) of this view -> homogeneous pixel coordinates in src1's rect:
  // temporal: the previous pose, or the interpolated poses of seed 003 Eq. 1 (one per sample);
  // stereo: [0] the other eye.
  glm::mat4 reproj[4];
  glm::vec4 sampleWeights;  // W(d_i) of seed 003 Eq. 2, one per reprojection
  glm::ivec2 src0Offset;    // src0's rect in its image; its size is also the dispatch size
  glm::ivec2 src0Size;
  glm::vec2 src0InvExtent;  // 1 / src0's image extent
  glm::ivec2 src1Offset;    // src1's rect: the history (temporal) or the other eye (stereo)
  glm::ivec2 src1Size;
  glm::vec2 src1InvExtent;
  DepthToInvZ depth0;  // this eye's depth
  DepthToInvZ depth1;  // the other eye's depth (stereo)
  glm::ivec2 depth0Offset;
  glm::ivec2 depth1Offset;
  glm::ivec2 outOffset;          // where pixel (0, 0) goes in the output image
  glm::ivec2 appInputOffset;     // the app's input rect (uAppInput, the alpha of every output)
  glm::vec2 jitterPx;            // src0's grid offset in pixels: its pixel c - jitter holds our pixel c
  int32_t historyValid;          // temporal: 0 after a reset or an invalid pose
  float taaAlpha;                // taa: weight of the current frame; steady: its constant alpha (ablation)
  float clipGamma;               // variance clip box mean +- gamma*sigma (taa, hybrid, stereo; steady's own)
  float alphaMin;                // vtaa, hybrid: lower clamp of alpha' of seed 002 Eq. 4
  float shapeS;                  // hmtaa, hybrid: S of seed 003 Eq. 4 (A(h) with w_min = 0); 1: h > h_max
  float wMin;                    // hmtaa: w_min of seed 003 Eq. 5
  float wLowerBound;             // hmtaa: w_lb of seed 003 Eq. 5
  float fallbackInvZ;            // 1/z assumed without depth (1 / stereoFarDistanceM, 0 = infinity)
  float stereoDepthTolerance;    // stereo: relative depth difference that rejects the other eye
  float stereoBetaMin;           // stereo: lower clamp of beta (seed 002 Eq. 4)
  float steadyAlphaFloor;        // steady: alpha >= this; 1/floor caps the sample count
  float steadyConfidence;        // steady: 1 = alpha from the sample count, 0 = taaAlpha
  float steadyClipRejects;       // steady: 1 = a clip by t sigma divides the count by t^2 (a mix weight)
  float steadyInvBlurBudgetPx2;  // steady: 1 / blur budget (0 = no bound)
  float steadyFootprint;         // steady: k of the [k, 1 - 2k, k]^2 footprint filter (0 = off)
  float steadyFootprintEncoded;  // steady: 1 = that filter on square roots, 0 = in linear light
  uint32_t ditherSeed;           // the 8-bit history's dither: new every frame (common.glsl storeHistory)
  float
      stereoInverseVariance;  // stereo: 1 = beta by inverse error variance (after steady), 0 = seed 002 Eq. 4
  float stereoSampleCountScale;    // stereo: src alpha * this = the eye's sample count (>= 1); 0: count 1
  float stereoDisparitySpreadPx2;  // stereo without this eye's depth: the disparity's spread, px^2
  float steadyJitterRecentred;  // steady, jittered input: 1 = 3x3 weights follow the offset, 0 = raw sample
  float steadyHistoryBlurPerAxis;  // steady (history read): 1 = the blur guard per axis, 0 = summed
  float steadyClipHoldsCurrent;    // steady: 1 = the clip box reaches out to the current estimate fc
  float stereoTapCurvature;  // stereo: 1 = the other eye's bilinear tap corrected by this eye's curvature
  float steadyClipCurvatureKappa;  // steady: > 0 = the clip box bounded by kappa (|cxx| + |cyy|); 0 = off
  float steadyClipCurvatureInner;  // steady (round 7): the one-sided curvature box's inner bound (spec bit0)
  float steadyNoiseVariance;       // steady (round 13): the render's noise variance per linear RGB channel
  int32_t probeBlockPx;            // steady's probe (round 17): one sample per block of this side
  float steadyOutputHold;          // steady (round 20): the 8-bit output's hysteresis, codes beyond 1/2
  int32_t shownValid;              // steady (round 20): 1 = last frame's shown codes are this pass's
  int32_t headLockedStep;          // steady's probe (round 42): filter_head_locked.h's HeadLockedStep
  float headLockedInputDecoded;    // steady's probe (round 42): 1 = src0 is sRGB, read decoded to linear
  float headLockedDetailVariance;  // steady's probe (round 42): the frame's own finest detail, as a variance
};

// std140 offsets of PassParams in common.glsl: a host member moved fails here, a shader member
// moved fails tests/core/filter_test_uniform_layout.cpp (which reads the shaders' SPIR-V).
static_assert(offsetof(PassUniforms, reproj) == 0);
static_assert(offsetof(PassUniforms, sampleWeights) == 256);
static_assert(offsetof(PassUniforms, src0Offset) == 272);
static_assert(offsetof(PassUniforms, src0Size) == 280);
static_assert(offsetof(PassUniforms, src0InvExtent) == 288);
static_assert(offsetof(PassUniforms, src1Offset) == 296);
static_assert(offsetof(PassUniforms, src1Size) == 304);
static_assert(offsetof(PassUniforms, src1InvExtent) == 312);
static_assert(offsetof(PassUniforms, depth0) == 320);
static_assert(offsetof(PassUniforms, depth1) == 336);
static_assert(offsetof(PassUniforms, depth0Offset) == 352);
static_assert(offsetof(PassUniforms, depth1Offset) == 360);
static_assert(offsetof(PassUniforms, outOffset) == 368);
static_assert(offsetof(PassUniforms, appInputOffset) == 376);
static_assert(offsetof(PassUniforms, jitterPx) == 384);
static_assert(offsetof(PassUniforms, historyValid) == 392);
static_assert(offsetof(PassUniforms, taaAlpha) == 396);
static_assert(offsetof(PassUniforms, clipGamma) == 400);
static_assert(offsetof(PassUniforms, alphaMin) == 404);
static_assert(offsetof(PassUniforms, shapeS) == 408);
static_assert(offsetof(PassUniforms, wMin) == 412);
static_assert(offsetof(PassUniforms, wLowerBound) == 416);
static_assert(offsetof(PassUniforms, fallbackInvZ) == 420);
static_assert(offsetof(PassUniforms, stereoDepthTolerance) == 424);
static_assert(offsetof(PassUniforms, stereoBetaMin) == 428);
static_assert(offsetof(PassUniforms, steadyAlphaFloor) == 432);
static_assert(offsetof(PassUniforms, steadyConfidence) == 436);
static_assert(offsetof(PassUniforms, steadyClipRejects) == 440);
static_assert(offsetof(PassUniforms, steadyInvBlurBudgetPx2) == 444);
static_assert(offsetof(PassUniforms, steadyFootprint) == 448);
static_assert(offsetof(PassUniforms, steadyFootprintEncoded) == 452);
static_assert(offsetof(PassUniforms, ditherSeed) == 456);
static_assert(offsetof(PassUniforms, stereoInverseVariance) == 460);
static_assert(offsetof(PassUniforms, stereoSampleCountScale) == 464);
static_assert(offsetof(PassUniforms, stereoDisparitySpreadPx2) == 468);
static_assert(offsetof(PassUniforms, steadyJitterRecentred) == 472);
static_assert(offsetof(PassUniforms, steadyHistoryBlurPerAxis) == 476);
static_assert(offsetof(PassUniforms, steadyClipHoldsCurrent) == 480);
static_assert(offsetof(PassUniforms, stereoTapCurvature) == 484);
static_assert(offsetof(PassUniforms, steadyClipCurvatureKappa) == 488);
static_assert(offsetof(PassUniforms, steadyClipCurvatureInner) == 492);
static_assert(offsetof(PassUniforms, steadyNoiseVariance) == 496);
static_assert(offsetof(PassUniforms, probeBlockPx) == 500);
static_assert(offsetof(PassUniforms, steadyOutputHold) == 504);
static_assert(offsetof(PassUniforms, shownValid) == 508);
static_assert(offsetof(PassUniforms, headLockedStep) == 512);
static_assert(offsetof(PassUniforms, headLockedInputDecoded) == 516);
static_assert(offsetof(PassUniforms, headLockedDetailVariance) == 520);
static_assert(sizeof(PassUniforms) == 528);  // the block's 528 bytes (16-aligned by DepthToInvZ)

}  // namespace steadyxr::core
