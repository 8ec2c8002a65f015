// xrEndFrame top to bottom: Session::endFrame is the whole frame path as a list of named steps,
// and each step follows it below in the order it runs. What the steps check and copy of the
// app's structs are the pure helpers of rewrite.h (scanFrame, checkProjection, FrameRewrite),
// tested without a runtime; the layer's output swapchains are in session_output.cpp.
// Locking: see Session in session.h.
#include "session.h"

#include "steadyxr/core/view_math.h"

#include <glm/gtc/quaternion.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace steadyxr::layer {
namespace {

core::Pose toPose(const XrPosef& p) {
  core::Pose out;
  out.orientation = glm::quat(p.orientation.w, p.orientation.x, p.orientation.y, p.orientation.z);
  out.position = glm::vec3(p.position.x, p.position.y, p.position.z);
  return out;
}

core::Fov toFov(const XrFovf& f) {
  return {f.angleLeft, f.angleRight, f.angleUp, f.angleDown};
}

VkRect2D toRect(const XrRect2Di& r) {
  return {{r.offset.x, r.offset.y},
          {static_cast<uint32_t>(r.extent.width), static_cast<uint32_t>(r.extent.height)}};
}

// The region of a swapchain image that a sub-image names, as the filter core reads or writes it.
core::ImageRef imageRef(const XrSwapchainCreateInfo& info, VkImage image, const XrSwapchainSubImage& sub,
                        VkImageLayout layout) {
  core::ImageRef r;
  r.image = image;
  r.format = static_cast<VkFormat>(info.format);
  r.extent = {info.width, info.height};
  r.arrayLayer = sub.imageArrayIndex;
  r.arrayLayerCount = info.arraySize;
  r.rect = toRect(sub.imageRect);
  r.usage = vulkanUsage(info.usageFlags);
  r.mutableFormat = (info.usageFlags & XR_SWAPCHAIN_USAGE_MUTABLE_FORMAT_BIT) != 0;
  r.layout = layout;
  return r;
}

uint64_t spaceId(XrSpace space) {
  return reinterpret_cast<uint64_t>(space);  // XrSpace is a pointer or a 64-bit handle: both fit
}

VkExtent2D extentOf(const XrRect2Di& r) {
  return {static_cast<uint32_t>(std::max(r.extent.width, 0)),
          static_cast<uint32_t>(std::max(r.extent.height, 0))};
}

}  // namespace

// What one xrEndFrame carries from step to step. Lives on endFrame's stack.
struct Session::FrameWork {
  FrameWork(const XrFrameEndInfo& app, const FrameScan& s) : scan(s), rewrite(app) {
    input.displayTimeNs = app.displayTime;
    if (scan.projection)
      projection = reinterpret_cast<const XrCompositionLayerProjection*>(app.layers[*scan.projection]);
  }
  // One output swapchain per distinct app swapchain, acquired once this frame.
  struct AcquiredOutput {
    OwnedSwapchain* out;
    uint32_t index;
  };

  FrameScan scan;
  const XrCompositionLayerProjection* projection = nullptr;  // the app's layer the layer filters
  std::vector<ViewUnjitter> unjitter;  // per view while the layer's jitter is on, else empty
  uint32_t jitterMatched = 0;          // views of `unjitter` that the layer had jittered
  core::StereoFrame input;
  core::StereoOutput output;
  std::array<AppSwapchain*, 2> apps{};  // the app swapchain of each view
  std::map<XrSwapchain, AcquiredOutput> acquired;
  std::vector<XrSwapchain> outputSwapchains;  // per view: what the rewritten layer shows
  std::optional<PassReason> passReason;       // set: the projection layer goes down as the app sent it
  std::array<VkExtent2D, 2> filteredSizes{};  // per filtered view: its rect's size
  FrameRewrite rewrite;                       // the structs handed to the runtime
};

XrResult Session::endFrame(const XrFrameEndInfo* info) {
  applyLiveConfig();  // config file edits: enabled, method, pass parameters (session_live.cpp)
  publishStatus();    // about once a second
  const FrameScan scan = scanAppFrame(info);
  if (!scan.ok() || !filtering_ || !liveEnabled_) return passThrough(scan, info);
  std::unique_lock frameLock(frameMutex_);
  if (!filtering_ || shutDown_) {
    frameLock.unlock();
    return passThrough(scan, info);
  }
  FrameWork work(*info, scan);
  // A step that fails sets passReason: the steps after it are skipped (output images acquired
  // are released either way) and the projection layer goes down as the app sent it. Head speed
  // is taken only for frames about to be filtered: it advances the speed's smoothing.
  if (work.projection) {
    matchJitter(work);
    work.passReason = chooseViews(work);
    if (!work.passReason) work.passReason = acquireOutputs(work);
    if (!work.passReason) {
      work.input.headSpeedDegPerSec = headSpeed(*work.projection, work.input.displayTimeNs);
      const uint64_t poseSpace = spaceId(work.projection->space);
      {
        std::lock_guard lock(mutex_);
        work.input.reset = continuity_.mustDrop(work.input.displayTimeNs, poseSpace);
      }
      work.passReason = runFilter(work);
      if (!work.passReason) {
        std::lock_guard lock(mutex_);
        continuity_.filtered(work.input.displayTimeNs, poseSpace);
        if (work.input.reset) ++stats_.historyDropped;
        stats_.renderSize = filter_->renderSizeCounters();
        stats_.imageMemoryBytes = filter_->imageMemoryBytes();
      }
    }
    releaseOutputs(work);
    if (!work.passReason) {
      recordTimings();
      rewriteProjection(work);
    }
  }
  frameLock.unlock();
  // The runtime call with no lock held: other threads' xrLocateViews and swapchain calls go on.
  const XrResult r = next().endFrame(handle_, work.rewrite.replacedCount() > 0 ? &work.rewrite.info() : info);
  countFrame(work, r);
  return r;
}

// Step 1. Nothing of the app's frame is read before scanFrame has checked it (issue 15:
// layers = NULL crashed here); a frame with a problem goes to the runtime exactly as the app
// submitted it.
FrameScan Session::scanAppFrame(const XrFrameEndInfo* info) {
  const FrameScan scan = scanFrame(info, maxLayerCount_);
  if (!scan.ok()) {
    instance_->log->once(LogLevel::Warn, "invalid-frame-" + std::string(toString(scan.problem)),
                         "xrEndFrame with " + std::string(toString(scan.problem)) +
                             ": forwarded untouched (the runtime answers it)");
  }
  return scan;
}

// A frame the layer does not filter at all (invalid, not Vulkan, switched off, shut down).
XrResult Session::passThrough(const FrameScan& scan, const XrFrameEndInfo* info) {
  if (vulkanSession_) countUnfiltered(scan);
  return next().endFrame(handle_, info);
}

// Step 2. Views rendered with the layer's jitter are filtered onto, and submitted with, the
// unjittered fov; any other fov (the app's own) is used as is with no jitter.
void Session::matchJitter(FrameWork& work) {
  const XrCompositionLayerProjection& proj = *work.projection;
  if (!jitter_ || proj.views == nullptr || proj.viewCount > JitterTracker::kMaxViews) return;
  std::lock_guard lock(mutex_);
  for (uint32_t v = 0; v < proj.viewCount; ++v) {
    work.unjitter.push_back(
        jitterTracker_.find(v, proj.views[v].fov, extentOf(proj.views[v].subImage.imageRect)));
    work.jitterMatched += work.unjitter.back().matched ? 1 : 0;
  }
}

// Step 3. Whether the projection layer can be filtered (checkProjection), and if so the app
// images, rects, poses and fovs the filter reads. Called with frameMutex_ held: the app's
// swapchain entries cannot disappear meanwhile (only erased under frameMutex_).
std::optional<PassReason> Session::chooseViews(FrameWork& work) {
  const XrCompositionLayerProjection& layer = *work.projection;
  ensureImages(layer);
  work.input.viewCount = layer.viewCount;
  std::lock_guard lock(mutex_);
  const auto lookup = [this](XrSwapchain s) -> std::optional<SwapchainFacts> {
    auto it = swapchains_.find(s);
    if (it == swapchains_.end()) return std::nullopt;
    return it->second.facts();
  };
  if (auto reason = checkProjection(layer, lookup)) return reason;
  for (uint32_t v = 0; v < layer.viewCount; ++v) {
    const XrCompositionLayerProjectionView& view = layer.views[v];
    AppSwapchain& app = swapchains_.at(view.subImage.swapchain);
    work.apps[v] = &app;
    core::ViewFrame& vf = work.input.views[v];
    // VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL: the Vulkan binding's layout at release.
    vf.color = imageRef(app.info, app.images[*app.released], view.subImage,
                        VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
    vf.pose = toPose(view.pose);
    const std::vector<ViewUnjitter>& unjitter = work.unjitter;
    if (v < unjitter.size() && unjitter[v].matched) {
      vf.fov = toFov(unjitter[v].fov);
      vf.jitterPx = {unjitter[v].jitterPx[0], unjitter[v].jitterPx[1]};
    } else {
      vf.fov = toFov(view.fov);
    }
    if (const XrCompositionLayerDepthInfoKHR* d = findDepthInfo(view)) vf.depth = appDepth(*d);
  }
  return std::nullopt;
}

// The depth image a view's XrCompositionLayerDepthInfoKHR names, when the filter can sample it.
// Called with mutex_ held.
std::optional<core::DepthRef> Session::appDepth(const XrCompositionLayerDepthInfoKHR& d) const {
  auto ds = swapchains_.find(d.subImage.swapchain);
  if (ds == swapchains_.end() || !ds->second.facts().hasReleasedImage ||
      !isDepthFormat(ds->second.info.format) ||
      !(ds->second.info.usageFlags & XR_SWAPCHAIN_USAGE_SAMPLED_BIT))
    return std::nullopt;
  core::DepthRef depth;
  depth.image = imageRef(ds->second.info, ds->second.images[*ds->second.released], d.subImage,
                         VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL);
  depth.minDepth = d.minDepth;
  depth.maxDepth = d.maxDepth;
  depth.nearZ = d.nearZ;
  depth.farZ = d.farZ;
  return depth;
}

// Step 4. An output image for each view: one output swapchain per distinct app swapchain,
// acquired once this frame (runtime calls; mutex_ not held).
std::optional<PassReason> Session::acquireOutputs(FrameWork& work) {
  const XrCompositionLayerProjection& layer = *work.projection;
  for (uint32_t v = 0; v < layer.viewCount; ++v) {
    const XrCompositionLayerProjectionView& view = layer.views[v];
    auto it = work.acquired.find(view.subImage.swapchain);
    if (it == work.acquired.end()) {
      OwnedSwapchain* out = ensureOutput(*work.apps[v]);
      if (!out) return PassReason::OutputSwapchain;
      uint32_t index = 0;
      if (auto failure = acquireOutput(*out, &index)) return failure;
      it = work.acquired.emplace(view.subImage.swapchain, FrameWork::AcquiredOutput{out, index}).first;
    }
    // The same sub-image of the output swapchain (same size and array size as the app's).
    const FrameWork::AcquiredOutput& acq = it->second;
    work.output.views[v] = imageRef(acq.out->info(), acq.out->images()[acq.index], view.subImage,
                                    VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);  // after xrWaitSwapchainImage
    work.outputSwapchains.push_back(acq.out->handle());
  }
  return std::nullopt;
}

// Step 5. The head's angular speed (deg/s) at the display time: from the IMU with
// pose_source = imu, else the runtime's VIEW space velocity when it reports one, else the
// change of the submitted head orientation over the change of display time; smoothed.
float Session::headSpeed(const XrCompositionLayerProjection& layer, int64_t displayTime) {
  if (imu_) {
    // XrTime -> CLOCK_MONOTONIC (the IMU source's host time domain) through
    // XR_KHR_convert_timespec_time, which the layer enables when pose_source = imu.
    std::optional<int64_t> hostNs;
    timespec ts{};
    if (next().convertTimeToTimespec != nullptr &&
        XR_SUCCEEDED(next().convertTimeToTimespec(instance_->handle, displayTime, &ts))) {
      hostNs = int64_t{ts.tv_sec} * 1'000'000'000 + ts.tv_nsec;
    }
    if (const std::optional<imu::HeadState> s = hostNs ? imu_->stateAt(*hostNs) : std::nullopt) {
      std::lock_guard lock(mutex_);
      ++stats_.imuFrames;
      return s->headSpeedDegPerSec;
    }
    {
      std::lock_guard lock(mutex_);
      ++stats_.imuFallbackFrames;
    }
    instance_->log->once(LogLevel::Warn, "imu-no-data",
                         "pose_source = imu: no IMU state at the display time; using the runtime's poses");
  }
  std::optional<float> raw;
  if (viewSpace_ != XR_NULL_HANDLE) {
    auto vel = makeXr<XrSpaceVelocity>(XR_TYPE_SPACE_VELOCITY);
    auto loc = makeXr<XrSpaceLocation>(XR_TYPE_SPACE_LOCATION, &vel);
    if (XR_SUCCEEDED(next().locateSpace(viewSpace_, layer.space, displayTime, &loc)) &&
        (vel.velocityFlags & XR_SPACE_VELOCITY_ANGULAR_VALID_BIT)) {
      const XrVector3f& w = vel.angularVelocity;
      raw = std::sqrt(w.x * w.x + w.y * w.y + w.z * w.z) * 57.29578f;
    }
  }
  const XrQuaternionf q = layer.views[0].pose.orientation;
  const double dt = (displayTime - lastDisplayTime_) * 1e-9;
  if (!raw && lastOrientation_ && layer.space == lastSpace_ && dt > 1e-4 && dt < 0.5) {
    const glm::quat a(lastOrientation_->w, lastOrientation_->x, lastOrientation_->y, lastOrientation_->z);
    const glm::quat b(q.w, q.x, q.y, q.z);
    raw = static_cast<float>(core::angleBetweenDeg(a, b) / dt);
  }
  if (raw && std::isfinite(*raw)) {
    const float k = static_cast<float>(1.0 - std::exp(-std::clamp(dt, 0.0, 0.5) / 0.05));  // ~50 ms
    smoothedSpeed_ = lastOrientation_ ? smoothedSpeed_ + k * (*raw - smoothedSpeed_) : *raw;
  }
  lastOrientation_ = q;
  lastDisplayTime_ = displayTime;
  lastSpace_ = layer.space;
  return smoothedSpeed_;
}

// Step 6. The filter core records and submits its passes from the app's images into the
// output images (steadyxr/core/filter.h); the dump, when asked for, reads both back.
std::optional<PassReason> Session::runFilter(FrameWork& work) {
  Logger& log = *instance_->log;
  if (log.enabled(LogLevel::Debug) && debugFrames_ < 10) {
    ++debugFrames_;
    const XrPosef& p = work.projection->views[0].pose;
    const XrFovf& f = work.projection->views[0].fov;
    char buf[256];
    std::snprintf(buf, sizeof buf,
                  "frame t=%lld view0 q=(%.6f %.6f %.6f %.6f) p=(%.4f %.4f %.4f) fov=(%.4f %.4f %.4f %.4f) "
                  "speed=%.3f deg/s",
                  static_cast<long long>(work.input.displayTimeNs), p.orientation.w, p.orientation.x,
                  p.orientation.y, p.orientation.z, p.position.x, p.position.y, p.position.z, f.angleLeft,
                  f.angleRight, f.angleUp, f.angleDown, work.input.headSpeedDegPerSec);
    log.log(LogLevel::Debug, buf);
  }
  std::string error;
  filter_->setDepthMayChange(appHasDepthSwapchain_);
  if (!filter_->submit(work.input, work.output, &error)) {
    if (filter_->compiling()) {
      log.once(LogLevel::Info, "filter-compiling",
               "the filter's pipelines are compiling in the background; frames pass through until then");
      return PassReason::Compiling;
    }
    log.once(LogLevel::Warn, "filter-submit", "filter: " + error);
    return PassReason::FilterError;
  }
  if (dumper_.wants()) dumper_.dump(*vk_, work.input, work.output, log);
  if (const auto evidence = filter_->headLockedEvidence(); evidence && evidence->decidedFrame) {
    log.once(LogLevel::Info, "head-locked-switch",
             "steady_head_locked_switch: the app draws head-locked content (a HUD, a reticle) into its eye "
             "images (found in filtered frame " +
                 std::to_string(*evidence->decidedFrame) +
                 "): the profile hud's settings for the rest of the session");
  }
  return std::nullopt;
}

// Step 7. Every output image acquired this frame goes back, filtered or not (the layer waits
// only on its own work; the runtime orders its reads after this queue's submissions).
void Session::releaseOutputs(FrameWork& work) {
  for (const auto& [app, acq] : work.acquired) {
    const XrResult r = next().releaseSwapchainImage(acq.out->handle(), nullptr);
    if (XR_FAILED(r)) {
      instance_->log->once(LogLevel::Warn, "release", xrError("xrReleaseSwapchainImage (layer output)", r));
      work.passReason = PassReason::XrError;
    }
  }
}

// The filter's GPU timings of its newest measured frame, added once to the session summary.
void Session::recordTimings() {
  const std::optional<core::PassTimings> t = filter_->lastTimings();
  if (!t) return;
  std::lock_guard lock(mutex_);
  if (t->frameIndex == stats_.lastTimingIndex) return;
  stats_.lastTimingIndex = t->frameIndex;
  ++stats_.timingFrames;
  stats_.temporalMs += t->temporalMs;
  stats_.stereoMs += t->stereoMs;
  stats_.otherMs += t->otherMs;
  stats_.totalMs += t->totalMs;
}

// Step 8. The runtime gets a copy of the app's frame whose projection layer shows the output
// images (and the unjittered fovs); the app's own structs are never written.
void Session::rewriteProjection(FrameWork& work) {
  std::vector<XrFovf> fovs;
  for (const ViewUnjitter& u : work.unjitter) fovs.push_back(u.fov);
  work.rewrite.replaceProjection(*work.scan.projection, work.outputSwapchains,
                                 work.jitterMatched > 0 ? &fovs : nullptr);
  for (uint32_t v = 0; v < work.projection->viewCount; ++v)
    work.filteredSizes[v] = extentOf(work.projection->views[v].subImage.imageRect);
}

// Step 9 (after the runtime's xrEndFrame). What became of the frame, for the session summary
// and the status file; a filtered frame's view sizes are what xrLocateViews jitters next.
void Session::countFrame(const FrameWork& work, XrResult runtimeResult) {
  std::lock_guard lock(mutex_);
  if (!work.projection) {
    ++stats_.framesEmpty;
    continuity_.frameWithoutWorld();
  } else if (work.passReason) {
    passed(*work.passReason, "projection layer left as the app submitted it");
  } else if (XR_FAILED(runtimeResult)) {
    // Filtered, but the runtime refused the frame: it was never shown.
    passed(PassReason::RuntimeRejected, xrError("xrEndFrame", runtimeResult));
  } else {
    for (uint32_t v = 0; v < work.unjitter.size(); ++v) {
      if (!work.unjitter[v].matched) continue;
      char buf[160];
      std::snprintf(buf, sizeof buf, "jitter: undone on submit (first: view %u, %.4f, %.4f px)", v,
                    work.unjitter[v].jitterPx[0], work.unjitter[v].jitterPx[1]);
      instance_->log->once(LogLevel::Info, "jitter-undone", buf);
      break;
    }
    stats_.jitterUndone += work.jitterMatched;
    stats_.jitterUnmatched += work.unjitter.size() - work.jitterMatched;
    const uint32_t viewCount = work.input.viewCount;
    for (uint32_t v = 0; v < viewCount; ++v) viewSize_[v] = work.filteredSizes[v];
    ++stats_.framesFiltered;
    for (uint32_t v = 0; v < viewCount; ++v) ++stats_.viewsFiltered[v];
  }
}

// A frame that went down untouched: why, for the summary.
void Session::countUnfiltered(const FrameScan& scan) {
  std::lock_guard lock(mutex_);
  if (!scan.ok()) {
    ++stats_.passed[static_cast<size_t>(PassReason::InvalidFrame)];
  } else if (scan.projection) {
    // Filtering but switched off live (`enabled = 0` in the config file): disabled, not failed.
    ++(filtering_ ? stats_.framesDisabled : stats_.passed[static_cast<size_t>(failedReason_)]);
  } else {
    ++stats_.framesEmpty;
    continuity_.frameWithoutWorld();
  }
}

// Called with mutex_ held.
void Session::passed(PassReason reason, const std::string& detail) {
  ++stats_.passed[static_cast<size_t>(reason)];
  if (reason == PassReason::Compiling) {  // expected for the first frames: logged once at info
    if (stats_.framesFiltered > 0) ++stats_.warmingUpLate;
    return;
  }
  instance_->log->once(LogLevel::Warn, "pass-" + std::string(toString(reason)),
                       "passing frames through (" + std::string(toString(reason)) + "): " + detail);
}

}  // namespace steadyxr::layer
