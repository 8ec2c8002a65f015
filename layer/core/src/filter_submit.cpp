// Filter::Impl::submit: check the frame, prepare each eye's history, bind the images, record the
// passes, submit; each step its own function, in that order.
#include <algorithm>
#include <array>
#include <string>

#include <glm/geometric.hpp>

#include "filter_error.h"
#include "filter_formats.h"
#include "filter_geometry.h"
#include "filter_impl.h"
#include "steadyxr/core/view_math.h"

namespace steadyxr::core {

using detail::copyPass;
using detail::EyeState;
using detail::fail;
using detail::finiteFov;
using detail::finitePose;
using detail::FramePlan;
using detail::fxaaPass;
using detail::isBgra;
using detail::isDepthFormat;
using detail::isOutputFormat;
using detail::isSrgb;
using detail::isUnorm8;
using detail::kOut16;
using detail::kOut8;
using detail::OwnedImage;
using detail::PassContext;
using detail::PassDispatch;
using detail::probePass;
using detail::rectInside;
using detail::sameExtent;
using detail::sampledLayout;
using detail::Slot;
using detail::stereoPass;
using detail::Target;
using detail::temporalPass;
using detail::validDepth;

namespace {

// After steady (inverse-variance beta) an eye blends the other only with a known disparity: its own
// depth, or a disparity spread without depth of at most a pixel (stereo.comp), and finite poses.
// When neither eye can, the stereo pass would copy this frame through the half-float history alone.
bool stereoBlendsNowhere(const Params& params, const StereoFrame& frame, const FramePlan& plan) {
  if (!plan.temporal || params.temporal != TemporalMethod::Steady || !params.stereoInverseVariance)
    return false;
  for (uint32_t e = 0; e < 2; ++e) {
    const uint32_t o = 1 - e;
    if (!plan.poseOk[e] || !plan.poseOk[o]) continue;
    if (plan.hasDepth[e]) return false;
    const ViewFrame& v = frame.views[e];
    if (detail::parallaxSpreadPx2(params, v, frame.views[o].pose, v.color.rect.extent) <= 1.0f) return false;
  }
  return true;
}

}  // namespace

bool Filter::Impl::submit(const StereoFrame& frame, const StereoOutput& output, std::string* error,
                          VkSemaphore signal) {
  pipelines.compiling = false;
  collectFinished();  // the newest noise estimate (and the head-locked switch's count), without waiting
  applyPendingParams();
  FramePlan plan;
  if (!checkInputs(frame, output, plan, error)) return false;
  if (!prepareEyes(frame, plan, error)) return false;
  if (!planHeadLocked(frame, plan, error)) return false;
  if (!bindTargets(frame, output, plan, error)) return false;

  Slot& s = beginRecording();
  std::vector<VkImageMemoryBarrier> backToFinal = transitionIn(s.cmd, frame, output, plan);
  timestamp(s, 0);
  bool ok = recordPasses(s, frame, output, plan, error);  // timestamps 4, 1 and 2
  if (pipelines.compiling) ok = false;  // no dispatch was recorded for the passes still compiling
  // Before the copy out: a staged output is copied to the app's image only where its pass ran.
  transitionOut(s.cmd, output, plan, ok, std::move(backToFinal));
  timestamp(s, 3);
  if (!submitRecording(s, signal, error)) return false;

  if (!ok) {
    for (auto& eye : eyes) eye.valid = false;
    headLocked.restartEpochs();  // the probe may not have taken this frame as its reference
    if (error && error->empty()) *error = "recording the filter commands failed";
    return false;
  }
  advanceEyes(frame, plan);
  return true;
}

void Filter::Impl::applyPendingParams() {
  if (paramsChanged && pendingParams.temporal != params.temporal) resetRequested = true;
  paramsChanged = false;
  if (resetRequested) headLocked = {};  // Filter::reset: what the filter learnt about the app goes too
  // The caller's params (pendingParams holds the newest), with the profile hud's settings once the
  // head-locked switch has decided (round 42): two uniforms, no new pipeline, the history kept.
  params = pendingParams.steadyHeadLockedSwitch && headLocked.decided() ? withHudProfile(pendingParams)
                                                                        : pendingParams;
}

bool Filter::Impl::planHeadLocked(const StereoFrame& frame, FramePlan& plan, std::string* error) {
  if (!params.steadyHeadLockedSwitch || !detail::probeRuns(params, plan)) return true;
  std::array<int32_t, 2> blockPx{};
  bool jittered = params.jitteredInput;
  for (uint32_t e = 0; e < plan.viewCount; ++e) {
    const ViewFrame& v = frame.views[e];
    blockPx[e] = detail::probeBlockPx(static_cast<int32_t>(v.color.rect.extent.width),
                                      static_cast<int32_t>(v.color.rect.extent.height));
    jittered = jittered || v.jitterPx.x != 0.0f || v.jitterPx.y != 0.0f;
  }
  plan.headLocked = headLocked.plan(frame, plan.poseOk, blockPx, jittered);
  for (uint32_t e = 0; e < plan.viewCount; ++e) {
    if (plan.headLocked[e].step != detail::HeadLockedStep::TakeReference) continue;
    OwnedImage& record = eyes[e].headLockedRecord;
    VkExtent2D extent = detail::headLockedRecordExtent(frame.views[e].color.rect.extent, blockPx[e]);
    // The probe overwrites every texel of its grid; a smaller grid (an app's dynamic resolution) fits.
    if (record.image && extent.width <= record.extent.width && extent.height <= record.extent.height)
      continue;
    if (record.image)
      extent = {std::max(extent.width, record.extent.width), std::max(extent.height, record.extent.height)};
    waitAll();
    if (!createImage(record, extent, VK_FORMAT_R16G16B16A16_SFLOAT,
                     VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT, error)) {
      headLocked.restartEpochs();
      return false;
    }
    record.clearOnInit = true;
  }
  return true;
}

bool Filter::Impl::checkInputs(const StereoFrame& frame, const StereoOutput& output, FramePlan& plan,
                               std::string* error) const {
  const uint32_t n = frame.viewCount;
  if (n < 1 || n > 2) return fail(error, "viewCount must be 1 or 2"), false;
  for (uint32_t e = 0; e < n; ++e) {
    const ViewFrame& v = frame.views[e];
    const ImageRef& out = output.views[e];
    if (!v.color.image || !out.image) return fail(error, "missing input or output image"), false;
    if (!rectInside(v.color) || !rectInside(out)) return fail(error, "image rect outside the image"), false;
    if (!sameExtent(v.color.rect.extent, out.rect.extent))
      return fail(error, "output rect size differs from the input rect size"), false;
    if (v.color.format == VK_FORMAT_UNDEFINED || isDepthFormat(v.color.format))
      return fail(error, "unsupported input colour format"), false;
    if (v.color.usage != 0 && !(v.color.usage & VK_IMAGE_USAGE_SAMPLED_BIT))
      return fail(error, "input image lacks SAMPLED usage"), false;
    if (!isOutputFormat(out.format)) return fail(error, "unsupported output format"), false;
    if (v.depth) {
      if (!v.depth->image.image || !validDepth(*v.depth) || !rectInside(v.depth->image) ||
          !sameExtent(v.depth->image.rect.extent, v.color.rect.extent))
        return fail(error, "invalid depth image (format, range or rect)"), false;
      plan.hasDepth[e] = true;
    }
  }
  const TemporalMethod method = params.temporal;
  plan.viewCount = n;
  plan.temporal = method == TemporalMethod::Taa || method == TemporalMethod::Hmtaa ||
                  method == TemporalMethod::Vtaa || method == TemporalMethod::Hybrid ||
                  method == TemporalMethod::Steady;
  plan.fxaa = method == TemporalMethod::Fxaa;
  plan.stereo = params.stereo && n == 2;
  plan.firstStage = plan.temporal || plan.fxaa || !plan.stereo;  // `none` + stereo reads the inputs directly
  return true;
}

namespace {

// How large view e's rect can grow at its offset: to the edge of the app's image, short of the other view's
// rect where both share the image and its layer (side by side, or one above the other), since an app never
// renders one eye into the other's part.
VkExtent2D roomForRect(const StereoFrame& frame, uint32_t viewCount, uint32_t e) {
  const ImageRef& in = frame.views[e].color;
  const int64_t x0 = in.rect.offset.x, y0 = in.rect.offset.y;
  int64_t right = in.extent.width, bottom = in.extent.height;
  for (uint32_t o = 0; o < viewCount; ++o) {
    const ImageRef& other = frame.views[o].color;
    if (o == e || other.image != in.image || other.arrayLayer != in.arrayLayer) continue;
    if (other.rect.offset.x >= x0 + int64_t(in.rect.extent.width))
      right = std::min<int64_t>(right, other.rect.offset.x);
    else if (other.rect.offset.y >= y0 + int64_t(in.rect.extent.height))
      bottom = std::min<int64_t>(bottom, other.rect.offset.y);
  }
  return {static_cast<uint32_t>(std::max<int64_t>(right - x0, 0)),
          static_cast<uint32_t>(std::max<int64_t>(bottom - y0, 0))};
}

}  // namespace

bool Filter::Impl::prepareEyes(const StereoFrame& frame, FramePlan& plan, std::string* error) {
  const uint32_t n = plan.viewCount;
  // Internal images hold any rect up to their capacity; a rect that outgrows it, or a change of the
  // history format, reallocates them and drops the history.
  for (uint32_t e = 0; e < n; ++e) {
    EyeState& eye = eyes[e];
    const ImageRef& in = frame.views[e].color;
    const VkExtent2D size = in.rect.extent;
    const VkFormat histFormat = historyFormat(params, in.format);
    const bool held = detail::outputHeld(params);  // the 8-bit output's codes kept for the next frame
    const bool fits = size.width <= eye.capacity.width && size.height <= eye.capacity.height;
    if (!eye.history[0].image || !fits || eye.history[0].format != histFormat ||
        held != static_cast<bool>(eye.shown[0].image)) {
      // A rect that outgrows the images is an app changing its render size (dynamic resolution): from
      // then on they take the largest rect the app's image holds at this offset, short of the other eye's
      // part (roomForRect), as FSR2 allocates for its maximum render size, so that later changes keep the
      // history. The first size is taken as it is.
      VkExtent2D capacity = fits ? eye.capacity : size;
      if (eye.history[0].image && !fits) {
        const VkExtent2D room = roomForRect(frame, plan.viewCount, e);
        capacity = {std::max(size.width, room.width), std::max(size.height, room.height)};
      }
      plan.imagesReallocated = plan.imagesReallocated || eye.history[0].image;
      waitAll();
      const VkImageUsageFlags usage =
          VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
      for (auto& h : eye.history) {
        if (!createImage(h, capacity, histFormat, usage, error)) return false;
        h.clearOnInit = true;
      }
      for (auto& sh : eye.shown) {  // also the output's staging image (stagesHeldOutput)
        sh = OwnedImage{};
        if (held && !createImage(sh, capacity, VK_FORMAT_R8G8B8A8_UNORM,
                                 usage | VK_IMAGE_USAGE_TRANSFER_SRC_BIT, error))
          return false;
        sh.clearOnInit = true;
      }
      for (auto& sc : eye.scratch) sc = OwnedImage{};
      eye.capacity = capacity;
      eye.written = {};
      eye.valid = false;
    }
  }
  if (frame.reset || resetRequested) {
    for (auto& eye : eyes) eye.valid = false;
    resetRequested = false;
    noiseTracker.reset();  // a new start: the noise is measured again
    noiseNextFrame = frameCounter;
  }
  // A history is reprojected only from a finite pose, across a small enough head move. Across a change of
  // the render size only by steady: its blur guard bounds the blur of resampling the history at another
  // scale. The seed methods have no such bound, and a size that changes every frame blurs their history
  // frame after frame (plain taa 1.61x none's RMSE where starting afresh gives 1.00x:
  // `steadyxr-eval --render-sizes`, README "Dynamic resolution").
  const bool keptAcrossSizes = params.temporal == TemporalMethod::Steady;
  for (uint32_t e = 0; e < n; ++e) {
    const ViewFrame& v = frame.views[e];
    EyeState& eye = eyes[e];
    plan.poseOk[e] = finitePose(v.pose) && finiteFov(v.fov);
    if (!plan.poseOk[e]) {
      eye.valid = false;
    } else if (eye.valid && !keptAcrossSizes &&
               !sameExtent(eye.written[historyIndex ^ 1u], v.color.rect.extent)) {
      eye.valid = false;
    } else if (eye.valid) {
      const float angle = angleBetweenDeg(eye.prevPose.orientation, v.pose.orientation);
      const float dist = glm::length(eye.prevPose.position - v.pose.position);
      if (!(angle <= params.resetAngleDeg) || !(dist <= params.resetTranslationM)) eye.valid = false;
    }
  }
  if (plan.stereo && stereoBlendsNowhere(params, frame, plan)) plan.stereo = false;
  return true;
}

// Round 40: where the output is held (writesHeldOutput), its codes' image can be the output's
// staging image: the pass stores the codes once and a transfer copies them to the app's image. On a CPU
// device (blocksPixels) that pays: lavapipe's shader store of an 8-bit pixel costs about 0.6 of the copy
// pass, its transfer copy a fraction of that (steadyxr-bench: README, Cost). A GPU stores to the app's image
// itself, where the copy would add a read of every pixel, unless that image takes no storage writes and needs
// a copy anyway.
bool Filter::Impl::stagesHeldOutput(const detail::FramePlan& plan, uint32_t e, bool directStorage) const {
  return detail::writesHeldOutput(params, plan, eyes[e], e) && (blocksPixels() || !directStorage);
}

bool Filter::Impl::bindTargets(const StereoFrame& frame, const StereoOutput& output, FramePlan& plan,
                               std::string* error) {
  const uint32_t n = plan.viewCount;
  // Output targets: direct storage writes where possible, else an intermediate and a copy.
  for (uint32_t e = 0; e < n; ++e) {
    const ImageRef& out = output.views[e];
    Target& t = plan.targets[e];
    const bool is16 = out.format == VK_FORMAT_R16G16B16A16_SFLOAT;
    const VkFormat viewFormat = is16 ? VK_FORMAT_R16G16B16A16_SFLOAT : VK_FORMAT_R8G8B8A8_UNORM;
    t.fmt = is16 ? kOut16 : kOut8;
    t.srgb = isSrgb(out.format);
    t.swap = isBgra(out.format);
    VkFormatProperties fp;
    vkGetPhysicalDeviceFormatProperties(ctx.physicalDevice(), viewFormat, &fp);
    const bool storageOk = (fp.optimalTilingFeatures & VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT) != 0;
    const bool direct = (out.usage & VK_IMAGE_USAGE_STORAGE_BIT) && storageOk &&
                        (out.format == viewFormat || out.mutableFormat);
    if (stagesHeldOutput(plan, e, direct) && (out.usage & VK_IMAGE_USAGE_TRANSFER_DST_BIT)) {
      // Round 40: the pass writes the held output once, into its codes' image, and a copy takes it to the
      // app's image (the codes in the app's channel order: Target::codesBgra).
      t.scratch = &eyes[e].shown[historyIndex];
      t.holdsShownCodes = true;
      t.view = t.scratch->view.get();
    } else if (direct) {
      t.view = view(out.image, viewFormat, out.arrayLayer, VK_IMAGE_ASPECT_COLOR_BIT, error);
      if (!t.view) return false;
    } else if (out.usage & VK_IMAGE_USAGE_TRANSFER_DST_BIT) {
      OwnedImage& sc = eyes[e].scratch[t.fmt];
      if (!sc.image) {  // as large as the history: any rect that keeps it fits
        const VkImageUsageFlags usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
        if (!createImage(sc, eyes[e].capacity, viewFormat, usage, error)) return false;
      }
      t.scratch = &sc;
      t.view = sc.view.get();
    } else {
      return fail(error,
                  "output image needs STORAGE (storage-capable or mutable format) or TRANSFER_DST usage"),
             false;
    }
  }
  // The app's images as the passes sample them.
  for (uint32_t e = 0; e < n; ++e) {
    const ImageRef& in = frame.views[e].color;
    plan.inputs[e] = {view(in.image, in.format, in.arrayLayer, VK_IMAGE_ASPECT_COLOR_BIT, error),
                      sampledLayout(in.layout, false), isUnorm8(in.format)};
    if (!plan.inputs[e].view) return false;
    if (plan.hasDepth[e]) {
      const ImageRef& d = frame.views[e].depth->image;
      plan.depths[e] = {view(d.image, d.format, d.arrayLayer, VK_IMAGE_ASPECT_DEPTH_BIT, error),
                        sampledLayout(d.layout, true)};
      if (!plan.depths[e].view) return false;
    }
  }
  return true;
}

namespace {
void memoryBarrier(VkCommandBuffer cmd, VkPipelineStageFlags srcStage, VkAccessFlags srcAccess,
                   VkPipelineStageFlags dstStage, VkAccessFlags dstAccess) {
  VkMemoryBarrier m{};
  m.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
  m.srcAccessMask = srcAccess;
  m.dstAccessMask = dstAccess;
  vkCmdPipelineBarrier(cmd, srcStage, dstStage, 0, 1, &m, 0, nullptr, 0, nullptr);
}
}  // namespace

bool Filter::Impl::recordPasses(Slot& s, const StereoFrame& frame, const StereoOutput& output,
                                const FramePlan& plan, std::string* error) {
  Recording rec{s};
  const bool steady = plan.temporal && params.temporal == TemporalMethod::Steady;
  const float noiseVariance =
      !params.steadyNoiseEstimate ? params.steadyNoiseVariance : noiseTracker.variance().value_or(0.0f);
  const PassContext c{frame,
                      output,
                      params,
                      plan,
                      eyes,
                      historyIndex,
                      static_cast<uint32_t>(frameCounter),
                      noiseVariance,
                      noiseTracker.frameDetailVariance().value_or(0.0f)};
  for (uint32_t e = 0; e < plan.viewCount; ++e) eyes[e].shownWritten = detail::writesHeldOutput(c, e);
  s.noiseSampled = steady && plan.firstStage && params.steadyNoiseEstimate;
  s.gainProbed = false;
  const bool probesGain = steady && plan.firstStage && params.steadyGainCompensation;
  const bool probes = detail::probeRuns(params, plan);  // for the noise samples, the gain or both
  s.headLockedTestified =
      probes && std::any_of(plan.headLocked.begin(), plan.headLocked.end(),
                            [](const auto& h) { return h.step == detail::HeadLockedStep::Testify; });
  if (probes) zeroRecords(s);
  bool ok = true;
  if (probes) ok = recordProbes(rec, c, probesGain, error);
  timestamp(s, 4);  // the probe's part of the first stage (without one, only the timestamps' own cost)
  if (ok && plan.firstStage) {
    for (uint32_t e = 0; e < plan.viewCount && ok; ++e) {
      const PassDispatch d = plan.temporal ? temporalPass(c, e) : plan.fxaa ? fxaaPass(c, e) : copyPass(c, e);
      ok = record(rec, d, error);
    }
  }
  if (s.noiseSampled || s.gainProbed) copyRecordsOut(s);  // for collect(), in cached memory
  if (ok && plan.stereo && plan.firstStage) {  // the first stage's history writes before stereo reads them
    memoryBarrier(s.cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                  VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
  }
  timestamp(s, 1);
  if (ok && plan.stereo) {
    for (uint32_t e = 0; e < 2 && ok; ++e) ok = record(rec, stereoPass(c, e), error);
  }
  timestamp(s, 2);
  return ok;
}

// The frame's noise and gain records zeroed on the GPU before the passes add to them.
void Filter::Impl::zeroRecords(Slot& s) {
  vkCmdFillBuffer(s.cmd, s.ubo.get(), s.noiseOffset, detail::kStorageBufferBytes, 0);
  memoryBarrier(s.cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
}

// The records' atomic adds copied into host-cached memory and made visible to the host (collect).
void Filter::Impl::copyRecordsOut(Slot& s) {
  memoryBarrier(s.cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
  const VkBufferCopy region{s.noiseOffset, 0, detail::kStorageBufferBytes};
  vkCmdCopyBuffer(s.cmd, s.ubo.get(), s.records.get(), 1, &region);
  memoryBarrier(s.cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
}

// Round 16: both eyes' probes into the zeroed records (the gain's, made visible to the temporal passes that
// read it; round 22: the noise samples too).
bool Filter::Impl::recordProbes(Recording& rec, const PassContext& c, bool probesGain, std::string* error) {
  std::array<PassDispatch, 2> probes;
  bool observes = false;  // round 42: the head-locked switch's step in this frame (its own pipeline)
  for (uint32_t e = 0; e < c.plan.viewCount; ++e) {
    probes[e] = probePass(c, e);
    observes = observes || probes[e].uniforms.headLockedStep != 0;
  }
  if (params.steadyHeadLockedSwitch) {
    // Its pipeline is asked for in every frame until made, so that an epoch seldom waits for it; an epoch
    // whose pipeline is still compiling starts again (this frame passes nothing on to the next).
    bool ready = true;
    for (uint32_t e = 0; e < c.plan.viewCount; ++e) {
      PassDispatch observing = probes[e];
      observing.uniforms.headLockedStep = static_cast<int32_t>(detail::HeadLockedStep::Testify);
      ready = pipelines.ready(observing.pass, observing.fmt, specKeyOf(observing)) && ready;
    }
    if (observes && !ready) {
      for (uint32_t e = 0; e < c.plan.viewCount; ++e) {
        probes[e].uniforms.headLockedStep = 0;
        probes[e].io.headLockedRecord = VK_NULL_HANDLE;
      }
      headLocked.restartEpochs();
      rec.slot.headLockedTestified = false;
    }
    // Round 44: an epoch's frame waits for the plain probe too, which every other frame runs. Filtered
    // before it is made, it would be followed by frames that pass through while it compiles, each one
    // restarting the history and the epochs (filtered and passed through in turn).
    for (uint32_t e = 0; e < c.plan.viewCount && probes[e].uniforms.headLockedStep != 0; ++e) {
      PassDispatch plain = probes[e];
      plain.uniforms.headLockedStep = 0;
      if (!pipelines.get(plain.pass, plain.fmt, specKeyOf(plain), error) && !pipelines.compiling)
        return false;
    }
  }
  // Every frame, also one without a history (the probe then adds no gain): its pipeline is asked for with
  // the temporal pass's, so no later frame waits for it to compile (and passes through meanwhile).
  for (uint32_t e = 0; e < c.plan.viewCount; ++e) {
    if (!record(rec, probes[e], error)) return false;
  }
  rec.slot.gainProbed = probesGain;
  memoryBarrier(rec.slot.cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
  return true;
}

bool Filter::Impl::submitRecording(Slot& s, VkSemaphore signal, std::string* error) {
  if (vkEndCommandBuffer(s.cmd) != VK_SUCCESS) {
    fail(error, "vkEndCommandBuffer failed");
    return false;  // nothing was submitted; the slot stays free
  }
  // Even a failed recording is submitted when it holds the layout transitions, so the images end in
  // finalLayout; a failed dispatch only leaves the output unwritten.
  VkSubmitInfo si{};
  si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
  si.commandBufferCount = 1;
  si.pCommandBuffers = &s.cmd;
  if (signal) {
    si.signalSemaphoreCount = 1;
    si.pSignalSemaphores = &signal;
  }
  if (VkResult r = vkQueueSubmit(ctx.queue(), 1, &si, s.fence.get()); r != VK_SUCCESS) {
    return fail(error, "vkQueueSubmit failed: " + std::to_string(r)), false;
  }
  s.pending = true;
  s.timed = static_cast<bool>(s.queries);
  s.frameIndex = frameCounter++;
  return true;
}

void Filter::Impl::advanceEyes(const StereoFrame& frame, const FramePlan& plan) {
  bool resized = false, keptResized = false;
  for (uint32_t e = 0; e < plan.viewCount; ++e) {
    EyeState& eye = eyes[e];
    const VkExtent2D size = frame.views[e].color.rect.extent;
    resized = resized || (eye.lastSize.width != 0 && !sameExtent(eye.lastSize, size));
    // This frame read the history (valid before this update) written at another size.
    keptResized =
        keptResized || (plan.temporal && eye.valid && !sameExtent(eye.written[historyIndex ^ 1u], size));
    eye.lastSize = size;
    eye.valid = plan.temporal && plan.poseOk[e];
    eye.shownValid = eye.shownWritten;
    eye.shownBgra = plan.targets[e].codesBgra();
    eye.written[historyIndex] = size;
    if (plan.poseOk[e]) {
      eye.prevPose = frame.views[e].pose;
      eye.prevFov = frame.views[e].fov;
    }
  }
  historyIndex ^= 1u;
  sizeCounters.framesResized += resized;
  sizeCounters.historyKeptResized += keptResized;
  sizeCounters.imagesReallocated += plan.imagesReallocated;
}

VkFormat historyFormat(const Params& params, VkFormat inputFormat) {
  const bool history8 = params.historyFormat != HistoryFormat::Rgba16f && !params.stereo &&
                        params.historyFilter == HistoryFilter::Bilinear && isUnorm8(inputFormat);
  return history8 ? VK_FORMAT_R8G8B8A8_UNORM : VK_FORMAT_R16G16B16A16_SFLOAT;
}

}  // namespace steadyxr::core
