// One unit per pass on the host side: what it reads and writes, its specialisation key and its
// uniforms (copy, fxaa, temporal, stereo).
#include "filter_passes.h"

#include <algorithm>
#include <cmath>

#include "filter_formats.h"
#include "filter_geometry.h"
#include "steadyxr/core/view_math.h"

namespace steadyxr::core::detail {

namespace {

// The uniforms every pass of eye e shares: its input rect, where its output goes, the
// parameters, and this eye's depth.
PassUniforms baseUniforms(const PassContext& c, uint32_t e) {
  const Params& params = c.params;
  const float invFar = std::isinf(params.stereoFarDistanceM) ? 0.0f : 1.0f / params.stereoFarDistanceM;
  const float h = c.frame.headSpeedDegPerSec;
  const float shape = std::isfinite(h) && h <= params.hMaxDegPerSec
                          ? globalWeightA(h, params.hMaxDegPerSec, 0.0f)
                          : 1.0f;  // seed 003 Eq. 4 with w_min = 0: S
  PassUniforms u{};
  const ImageRef& in = c.frame.views[e].color;
  u.src0Offset = {in.rect.offset.x, in.rect.offset.y};
  u.src0Size = {in.rect.extent.width, in.rect.extent.height};
  u.src0InvExtent = {1.0f / static_cast<float>(in.extent.width), 1.0f / static_cast<float>(in.extent.height)};
  const ImageRef& out = c.output.views[e];
  if (!c.plan.targets[e].scratch) u.outOffset = {out.rect.offset.x, out.rect.offset.y};
  u.appInputOffset = {in.rect.offset.x, in.rect.offset.y};
  u.taaAlpha = params.taaAlpha;
  u.clipGamma = params.taaClipGamma;
  u.alphaMin = params.vtaaAlphaMin;
  u.shapeS = shape;
  u.wMin = params.wMin;
  u.wLowerBound = params.wLowerBound;
  u.stereoDepthTolerance = params.stereoDepthTolerance;
  u.fallbackInvZ = invFar;
  if (c.plan.hasDepth[e]) {
    u.depth0 = depthToInvZ(*c.frame.views[e].depth);
    const auto& r = c.frame.views[e].depth->image.rect;
    u.depth0Offset = {r.offset.x, r.offset.y};
  }
  return u;
}

PassSwitches baseSwitches(const PassContext& c, uint32_t e) {
  PassSwitches sw;
  sw.encodeSrgb = c.plan.targets[e].srgb;
  sw.swapRedBlue = c.plan.targets[e].swap;
  sw.inputSrgb = isSrgb(c.frame.views[e].color.format);
  sw.depthBits = c.plan.hasDepth[e] ? 1 : 0;
  return sw;
}

Binding historyBinding(const PassContext& c, uint32_t e, uint32_t i) {
  return Binding{c.eyes[e].history[i].view.get(), VK_IMAGE_LAYOUT_GENERAL, true};
}
glm::ivec2 sizeOf(VkExtent2D x) {
  return {x.width, x.height};
}
// The rect last frame's history holds (this frame's before it has one: a history not read).
VkExtent2D historyReadSize(const PassContext& c, uint32_t e) {
  return c.eyes[e].valid ? c.eyes[e].written[c.historyWrite ^ 1u] : c.frame.views[e].color.rect.extent;
}
glm::vec2 historyInvExtent(const PassContext& c, uint32_t e) {
  const VkExtent2D x = c.eyes[e].capacity;
  return {1.0f / static_cast<float>(x.width), 1.0f / static_cast<float>(x.height)};
}

// What copy, fxaa and temporal share: read the input, write this frame's history when stereo
// follows or the method is temporal, and the output when no stereo pass follows.
PassDispatch firstStage(const PassContext& c, uint32_t e, Pass pass) {
  PassDispatch d;
  d.pass = pass;
  d.uniforms = baseUniforms(c, e);
  d.switches = baseSwitches(c, e);
  const bool stereo = c.plan.stereo;
  d.fmt = stereo ? kOut8 : c.plan.targets[e].fmt;
  d.switches.writeOutput = !stereo;
  d.switches.writeHistory = c.plan.temporal || stereo;
  d.io.src0 = c.plan.inputs[e];
  d.io.appInput = c.plan.inputs[e];
  d.io.historyOut = d.switches.writeHistory ? c.eyes[e].history[c.historyWrite].view.get() : VK_NULL_HANDLE;
  // The history's format (historyFormat) decides how it is written and read back.
  const bool history8 = c.eyes[e].history[0].format == VK_FORMAT_R8G8B8A8_UNORM;
  d.switches.historyEncoding = !history8 ? 0 : c.params.historyFormat == HistoryFormat::Rgba8Nearest ? 2 : 1;
  d.uniforms.ditherSeed = c.ditherSeed;
  d.io.output = stereo ? VK_NULL_HANDLE : c.plan.targets[e].view;
  return d;
}

}  // namespace

PassDispatch copyPass(const PassContext& c, uint32_t e) {
  return firstStage(c, e, Pass::Copy);
}

PassDispatch fxaaPass(const PassContext& c, uint32_t e) {
  return firstStage(c, e, Pass::Fxaa);
}

bool writesHeldOutput(const Params& params, const FramePlan& plan, const EyeState& eye, uint32_t e) {
  return outputHeld(params) && plan.temporal && eye.shown[0].image && !plan.stereo &&
         plan.targets[e].fmt == kOut8;
}

bool writesHeldOutput(const PassContext& c, uint32_t e) {
  return writesHeldOutput(c.params, c.plan, c.eyes[e], e);
}

PassDispatch temporalPass(const PassContext& c, uint32_t e) {
  PassDispatch d = firstStage(c, e, Pass::Temporal);
  PassUniforms& u = d.uniforms;
  const Params& params = c.params;
  const TemporalMethod method = params.temporal;
  const ViewFrame& v = c.frame.views[e];
  const EyeState& eye = c.eyes[e];
  d.io.src1 = historyBinding(c, e, c.historyWrite ^ 1u);
  d.io.depth0 = c.plan.depths[e];
  const VkExtent2D historySize = historyReadSize(c, e);  // the app's render size may have changed since
  u.src1Offset = {0, 0};
  u.src1Size = sizeOf(historySize);
  u.src1InvExtent = historyInvExtent(c, e);
  u.historyValid = eye.valid ? 1 : 0;
  // Round 20: the 8-bit output keeps last frame's codes (storeHeldOutput); a float output is not rounded.
  if (writesHeldOutput(c, e)) {
    d.io.shownIn = Binding{eye.shown[c.historyWrite ^ 1u].view.get(), VK_IMAGE_LAYOUT_GENERAL, true};
    // Round 40: the output may be this frame's codes image itself (Target::holdsShownCodes, in the app's
    // channel order), copied to the app's image after the pass.
    const Target& t = c.plan.targets[e];
    d.io.outputIsShown = t.holdsShownCodes;
    if (!t.holdsShownCodes) d.io.shownOut = eye.shown[c.historyWrite].view.get();
    u.steadyOutputHold = params.steadyOutputHold;
    // Last frame's codes were written by this pass, in the channel order this frame reads them in.
    u.shownValid = eye.valid && eye.shownValid && eye.shownBgra == t.codesBgra() ? 1 : 0;
  }
  // Seed 003 Eq. 1: the past samples through poses interpolated between the previous and this
  // one, weighted by W(d_i) of Eq. 2 (hmtaa, hybrid; steady when steadyInterpolated, one sample).
  const bool steady = method == TemporalMethod::Steady;
  const bool interpolated = method == TemporalMethod::Hmtaa || method == TemporalMethod::Hybrid ||
                            (steady && params.steadyInterpolated);
  const uint32_t count = interpolated && !steady ? params.sampleCount : 1u;
  std::array<float, Params::kMaxSamples> w{};
  sampleWeightsW(params.sampleD.data(), count, w.data());
  for (uint32_t i = 0; i < count && eye.valid; ++i) {
    const Pose at = interpolated ? interpolatePose(eye.prevPose, v.pose, params.sampleD[i]) : eye.prevPose;
    u.reproj[i] = reprojection(v.pose, v.fov, v.color.rect.extent, at, eye.prevFov, historySize);
    u.sampleWeights[static_cast<int>(i)] = w[i];
  }
  d.switches.mode = method == TemporalMethod::Taa     ? kModeTaa
                    : method == TemporalMethod::Hmtaa ? kModeHmtaa
                    : method == TemporalMethod::Vtaa  ? kModeVtaa
                    : steady                          ? kModeSteady
                                                      : kModeHybrid;
  d.switches.sampleCount = static_cast<int32_t>(count);
  if (steady) {  // the steady mode's own uniforms (common.glsl, PassParams)
    u.clipGamma = params.steadyClipGamma;
    u.steadyAlphaFloor = params.steadyAlphaFloor;
    u.steadyConfidence = params.steadyConfidence ? 1.0f : 0.0f;
    u.steadyClipRejects = params.steadyClipRejects ? 1.0f : 0.0f;
    u.steadyInvBlurBudgetPx2 = params.steadyBlurBudgetPx2 > 0.0f ? 1.0f / params.steadyBlurBudgetPx2 : 0.0f;
    u.steadyFootprint = params.steadyFootprint;
    u.steadyFootprintEncoded = params.steadyFootprintEncoded ? 1.0f : 0.0f;
    u.steadyJitterRecentred = params.steadyJitterRecentred ? 1.0f : 0.0f;
    u.steadyHistoryBlurPerAxis = params.steadyHistoryBlurPerAxis ? 1.0f : 0.0f;
    u.steadyClipHoldsCurrent = params.steadyClipHoldsCurrent ? 1.0f : 0.0f;
    u.steadyNoiseVariance = c.noiseVariance;
    u.steadyClipCurvatureKappa = params.steadyClipCurvature ? params.steadyClipCurvatureKappa : 0.0f;
    u.steadyClipCurvatureInner = params.steadyClipCurvature && params.steadyClipCurvatureCentred
                                     ? params.steadyClipCurvatureInner
                                     : 0.0f;
  }
  u.jitterPx = v.jitterPx;
  if (!std::isfinite(u.jitterPx.x) || !std::isfinite(u.jitterPx.y) || std::abs(u.jitterPx.x) > 1.0f ||
      std::abs(u.jitterPx.y) > 1.0f)
    u.jitterPx = glm::vec2(0.0f);  // sub-pixel only; anything else is a caller bug: ignore it
  return d;
}

int64_t probeSamplesAlong(int64_t pixels, int32_t blockPx) {
  return std::max<int64_t>(0, (pixels + blockPx / 2 - 1) / blockPx);
}

int64_t probeSamples(int32_t width, int32_t height, int32_t blockPx) {
  return probeSamplesAlong(width, blockPx) * probeSamplesAlong(height, blockPx);
}

bool probeRuns(const Params& params, const FramePlan& plan) {
  return plan.temporal && plan.firstStage && params.temporal == TemporalMethod::Steady &&
         (params.steadyNoiseEstimate || params.steadyGainCompensation);
}

int32_t probeBlockPx(int32_t width, int32_t height) {
  int32_t block = kProbeSmallestBlockPx;
  while (probeSamples(width, height, block) > kProbeSamplesPerEye) ++block;  // ~sqrt(area / 1024) steps
  return block;
}

PassDispatch probePass(const PassContext& c, uint32_t e) {
  PassDispatch d = temporalPass(c, e);
  d.uniforms.probeBlockPx = probeBlockPx(d.uniforms.src0Size.x, d.uniforms.src0Size.y);
  d.switches.probe = true;
  d.switches.writeOutput = false;
  d.switches.writeHistory = false;
  d.io.output = VK_NULL_HANDLE;
  d.io.historyOut = VK_NULL_HANDLE;
  d.io.shownIn = Binding{};
  d.io.shownOut = VK_NULL_HANDLE;
  // Round 42: the head-locked switch's step (filter_head_locked.h), in the eye's record image.
  const HeadLockedEyeStep& headLocked = c.plan.headLocked[e];
  if (headLocked.step != HeadLockedStep::None && c.eyes[e].headLockedRecord.view) {
    d.uniforms.headLockedStep = static_cast<int32_t>(headLocked.step);
    d.uniforms.reproj[1] = headLocked.referenceToNow;
    d.uniforms.headLockedInputDecoded = d.switches.inputSrgb ? 1.0f : 0.0f;
    d.uniforms.headLockedDetailVariance = c.frameDetailVariance;
    d.io.headLockedRecord = c.eyes[e].headLockedRecord.view.get();
  }
  return d;
}

PassDispatch stereoPass(const PassContext& c, uint32_t e) {
  const uint32_t o = 1 - e;
  PassDispatch d;
  d.pass = Pass::Stereo;
  d.fmt = c.plan.targets[e].fmt;
  PassUniforms& u = d.uniforms;
  u = baseUniforms(c, e);
  d.switches = baseSwitches(c, e);
  d.switches.writeOutput = true;
  d.io = {c.plan.inputs[e],       c.plan.inputs[o], c.plan.depths[e], c.plan.depths[o], VK_NULL_HANDLE,
          c.plan.targets[e].view, c.plan.inputs[e], Binding{},        VK_NULL_HANDLE};
  const ImageRef& inO = c.frame.views[o].color;
  u.src1Offset = {inO.rect.offset.x, inO.rect.offset.y};
  u.src1Size = {inO.rect.extent.width, inO.rect.extent.height};
  u.src1InvExtent = {1.0f / static_cast<float>(inO.extent.width),
                     1.0f / static_cast<float>(inO.extent.height)};
  if (c.plan.firstStage) {  // the temporal/FXAA result sits in this frame's history image
    d.io.src0 = historyBinding(c, e, c.historyWrite);
    d.io.src1 = historyBinding(c, o, c.historyWrite);
    u.src0Offset = {0, 0};  // the same rect sizes as the inputs', at the images' top-left corners
    u.src0InvExtent = historyInvExtent(c, e);
    u.src1Offset = {0, 0};
    u.src1InvExtent = historyInvExtent(c, o);
  }
  if (c.plan.poseOk[e] && c.plan.poseOk[o]) {
    const ViewFrame& ve = c.frame.views[e];
    const ViewFrame& vo = c.frame.views[o];
    u.reproj[0] = reprojection(ve.pose, ve.fov, ve.color.rect.extent, vo.pose, vo.fov, vo.color.rect.extent);
  }  // else all zero: every reprojection fails and the eye is shown as is
  if (c.plan.hasDepth[o]) {
    u.depth1 = depthToInvZ(*c.frame.views[o].depth);
    const auto& r = c.frame.views[o].depth->image.rect;
    u.depth1Offset = {r.offset.x, r.offset.y};
    d.switches.depthBits |= 2;
  }
  u.stereoBetaMin = c.params.stereoBetaMin;
  // After steady the histories' alpha is each eye's sample count (RGBA16F: as is; stereo keeps it).
  const bool afterSteady = c.plan.temporal && c.params.temporal == TemporalMethod::Steady;
  u.stereoInverseVariance = afterSteady && c.params.stereoInverseVariance ? 1.0f : 0.0f;
  u.stereoSampleCountScale = afterSteady ? 1.0f : 0.0f;
  u.stereoTapCurvature = u.stereoInverseVariance > 0.5f && c.params.stereoTapCurvature ? 1.0f : 0.0f;
  if (u.stereoInverseVariance > 0.5f) u.clipGamma = c.params.stereoClipGammaAfterSteady;
  // Without this eye's depth the disparity is the far plane's; the true one lies anywhere up to
  // the nearest comfortable distance (steadyNearestDepthM), for the other eye's offset.
  if (!c.plan.hasDepth[e] && c.plan.poseOk[e] && c.plan.poseOk[o])
    u.stereoDisparitySpreadPx2 = parallaxSpreadPx2(c.params, c.frame.views[e], c.frame.views[o].pose,
                                                   c.frame.views[e].color.rect.extent);
  return d;
}

SpecKey passSpecKey(const PassDispatch& d, const Params& params, bool blocked, uint32_t groupX,
                    uint32_t groupY) {
  const PassSwitches& sw = d.switches;
  const bool temporal = d.pass == Pass::Temporal;
  const bool writeOut = sw.writeOutput;
  const bool jittered =
      params.jitteredInput || d.uniforms.jitterPx.x != 0.0f || d.uniforms.jitterPx.y != 0.0f;
  const bool oneSidedBox = params.steadyClipCurvature && params.steadyClipCurvatureCentred;
  return {
      temporal ? sw.mode : 0, temporal ? std::max(sw.sampleCount, 1) : 1, writeOut ? 1 : 0,
      sw.writeHistory ? 1 : 0, writeOut && sw.encodeSrgb ? 1 : 0, writeOut && sw.swapRedBlue ? 1 : 0,
      sw.depthBits, (d.io.src0.clean ? 1 : 0) | (d.io.src1.clean ? 2 : 0), temporal && jittered ? 1 : 0,
      temporal && params.historyFilter == HistoryFilter::CatmullRom ? 1 : 0, blocked ? 1 : 0,
      static_cast<int32_t>(groupX), static_cast<int32_t>(groupY), sw.historyEncoding,
      // Round 7's clip-box switches, compiled in only where on (lavapipe runs the default's
      // pipeline ~20 % slower with them behind uniform branches). The sRGB floor only where the
      // input is sRGB: UNORM input is filtered in its own codes, whose step is the linear floor.
      temporal
          ? (oneSidedBox ? 1 : 0) | (params.steadyClipQuantSrgb && sw.inputSrgb ? 2 : 0) |
                // Round 10's gate: its bit lives in the sign of the RGBA16F history's alpha.
                (oneSidedBox && params.steadyClipCurvatureCentredGated && sw.historyEncoding == 0 ? 4 : 0) |
                // Round 13: the box widened by the noise (the pass), and the histogram that estimates it
                // (round 14: with the residual's, where the host reads it), sampled by the probe since
                // round 22.
                (params.steadyNoiseEstimate || params.steadyNoiseVariance > 0.0f ? 8 : 0) |
                (sw.probe && params.steadyNoiseEstimate ? 16 : 0) |
                (sw.probe && params.steadyNoiseEstimate && params.steadyNoiseResidualOverTime ? 32 : 0) |
                // Round 16: the frame's gain, probed (128 with 64) and read by the pass (64); round 17: the
                // pass relights a history the box admits too, where the gain explains the change (256).
                (sw.probe ? 128 : 0) | (params.steadyGainCompensation ? 64 : 0) |
                (params.steadyGainCompensation && !sw.probe && params.steadyGainRelightsAdmitted ? 256 : 0) |
                // Round 20: the 8-bit output held (storeHeldOutput), where the pass binds the codes.
                (d.io.shownOut != VK_NULL_HANDLE || d.io.outputIsShown ? 512 : 0) |
                // Round 40: the output is the held codes' image (the pass stores them once; the host copies).
                (d.io.outputIsShown ? 4096 : 0) |
                // Round 26: the blur guard traded against the render's noise (per axis, with bit 8).
                (params.steadyBlurNoiseTrade && params.steadyHistoryBlurPerAxis ? 1024 : 0) |
                // Round 31: a frame the pose does not explain starts afresh (the probe's blocks, the pass).
                (params.steadyGainCompensation && params.steadyUnexplainedFrameResets ? 2048 : 0) |
                // Round 42: the head-locked switch's observations, compiled into the probe of an epoch's
                // frames only (lavapipe pays for the code in every invocation where it is compiled in: 0.6x
                // the copy at 256 px, in frames where no epoch ends).
                (sw.probe && d.uniforms.headLockedStep != 0 ? 8192 : 0) |
                // Round 48: beside an edge the app resolved, the frame as it is (the shader: with depth
                // only).
                (params.steadyResolvedEdges ? 16384 : 0)
          : 0};
}

}  // namespace steadyxr::core::detail
