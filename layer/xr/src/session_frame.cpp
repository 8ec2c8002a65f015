// The frame path of a session: xrEndFrame, its output swapchains and head speed, and the
// jitter injected into xrLocateViews. Locking: see Session in session.h.
#include "session.h"

#include "steadyxr/core/view_math.h"

#include <glm/gtc/quaternion.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>

namespace steadyxr::layer {
namespace {

constexpr XrDuration kOutputWaitNs = 1'000'000'000;  // bounded: never hang the frame loop

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

}  // namespace

OwnedSwapchain* Session::ensureOutput(AppSwapchain& app) {
  if (app.output) return app.output.get();
  XrSwapchainCreateInfo info = outputSwapchainInfo(app.info, mutableFormat_);
  if (dumper_.wants()) info.usageFlags |= XR_SWAPCHAIN_USAGE_TRANSFER_SRC_BIT;  // the dump reads it back
  XrSwapchain handle = XR_NULL_HANDLE;
  XrResult r = next().createSwapchain(handle_, &info, &handle);
  if (XR_FAILED(r)) {
    instance_->log->once(LogLevel::Warn, "output-create", xrError("xrCreateSwapchain (layer output)", r));
    return nullptr;
  }
  uint32_t n = 0;
  r = next().enumerateSwapchainImages(handle, 0, &n, nullptr);
  std::vector<XrSwapchainImageVulkanKHR> imgs(
      n, makeXr<XrSwapchainImageVulkanKHR>(XR_TYPE_SWAPCHAIN_IMAGE_VULKAN_KHR));
  if (XR_SUCCEEDED(r)) {
    r = next().enumerateSwapchainImages(handle, n, &n,
                                        reinterpret_cast<XrSwapchainImageBaseHeader*>(imgs.data()));
  }
  if (XR_FAILED(r) || n == 0) {
    next().destroySwapchain(handle);
    instance_->log->once(LogLevel::Warn, "output-enum",
                         xrError("xrEnumerateSwapchainImages (layer output)", r));
    return nullptr;
  }
  std::vector<VkImage> images;
  for (uint32_t i = 0; i < n; ++i) images.push_back(imgs[i].image);
  app.output = std::make_unique<OwnedSwapchain>(next(), handle, info, std::move(images));
  return app.output.get();
}

void Session::ensureImages(const XrCompositionLayerProjection& layer) {
  if (layer.views == nullptr || layer.viewCount < 1 || layer.viewCount > 2) return;
  // An app need not call xrEnumerateSwapchainImages itself (an engine may have its images
  // from elsewhere): the layer asks the runtime for those it has not seen yet.
  std::set<XrSwapchain> missing;
  {
    std::lock_guard lock(mutex_);
    auto consider = [&](XrSwapchain s) {
      auto it = swapchains_.find(s);
      if (it != swapchains_.end() && it->second.images.empty()) missing.insert(s);
    };
    for (uint32_t v = 0; v < layer.viewCount; ++v) {
      consider(layer.views[v].subImage.swapchain);
      if (const XrCompositionLayerDepthInfoKHR* d = findDepthInfo(layer.views[v]))
        consider(d->subImage.swapchain);
    }
  }
  for (XrSwapchain s : missing) {  // runtime calls: mutex_ not held
    uint32_t n = 0;
    if (XR_FAILED(next().enumerateSwapchainImages(s, 0, &n, nullptr)) || n == 0) continue;
    std::vector<XrSwapchainImageVulkanKHR> imgs(
        n, makeXr<XrSwapchainImageVulkanKHR>(XR_TYPE_SWAPCHAIN_IMAGE_VULKAN_KHR));
    if (XR_FAILED(next().enumerateSwapchainImages(
            s, n, &n, reinterpret_cast<XrSwapchainImageBaseHeader*>(imgs.data()))))
      continue;
    std::lock_guard lock(mutex_);
    if (auto it = swapchains_.find(s); it != swapchains_.end() && it->second.images.empty()) {
      for (uint32_t i = 0; i < n && i < imgs.size(); ++i) it->second.images.push_back(imgs[i].image);
    }
  }
}

std::optional<PassReason> Session::acquireOutput(OwnedSwapchain& out, uint32_t* index) {
  Logger& log = *instance_->log;
  if (!out.unwaited) {
    uint32_t i = 0;
    const XrResult r = next().acquireSwapchainImage(out.handle(), nullptr, &i);
    if (XR_FAILED(r)) {
      log.once(LogLevel::Warn, "acquire", xrError("xrAcquireSwapchainImage (layer output)", r));
      return PassReason::XrError;
    }
    out.unwaited = i;
  }
  auto wi = makeXr<XrSwapchainImageWaitInfo>(XR_TYPE_SWAPCHAIN_IMAGE_WAIT_INFO);
  wi.timeout = kOutputWaitNs;
  const XrResult r = next().waitSwapchainImage(out.handle(), &wi);
  // XR_SESSION_LOSS_PENDING is a success code: the wait succeeded. After XR_TIMEOUT_EXPIRED (or
  // an error) the image stays acquired and unwaited; the spec has the next wait wait on the same
  // image, so the next frame waits again instead of acquiring another.
  if (XR_SUCCEEDED(r) && r != XR_TIMEOUT_EXPIRED) {
    *index = *out.unwaited;
    out.unwaited.reset();
    return std::nullopt;
  }
  log.once(LogLevel::Warn, "output-wait",
           xrError("xrWaitSwapchainImage (layer output)", r) +
               "; frames pass through until a later frame's wait succeeds");
  return PassReason::XrError;
}

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
  // The runtime's VIEW space velocity when it reports one, else the change of the submitted
  // head orientation over the change of display time; smoothed either way.
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

// Called with frameMutex_ held. The app's swapchain entries cannot disappear meanwhile (only
// erased under frameMutex_) and their `output` is touched only under it.
std::optional<PassReason> Session::filterProjection(const XrCompositionLayerProjection& layer,
                                                    int64_t displayTime,
                                                    const std::vector<ViewUnjitter>& unjitter,
                                                    std::vector<XrSwapchain>* outputs) {
  Logger& log = *instance_->log;
  ensureImages(layer);
  core::StereoFrame frame;
  core::StereoOutput output;
  frame.viewCount = layer.viewCount;
  frame.displayTimeNs = displayTime;
  std::array<AppSwapchain*, 2> apps{};
  {  // what the frame needs of the app's swapchains, read under mutex_
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
      apps[v] = &app;
      const XrSwapchainCreateInfo& ai = app.info;
      core::ViewFrame& vf = frame.views[v];
      vf.color.image = app.images[*app.released];
      vf.color.format = static_cast<VkFormat>(ai.format);
      vf.color.extent = {ai.width, ai.height};
      vf.color.arrayLayer = view.subImage.imageArrayIndex;
      vf.color.arrayLayerCount = ai.arraySize;
      vf.color.rect = toRect(view.subImage.imageRect);
      vf.color.usage = vulkanUsage(ai.usageFlags);
      vf.color.mutableFormat = (ai.usageFlags & XR_SWAPCHAIN_USAGE_MUTABLE_FORMAT_BIT) != 0;
      vf.color.layout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;  // the Vulkan binding's layout at release
      vf.pose = toPose(view.pose);
      if (v < unjitter.size() && unjitter[v].matched) {
        vf.fov = toFov(unjitter[v].fov);
        vf.jitterPx = {unjitter[v].jitterPx[0], unjitter[v].jitterPx[1]};
      } else {
        vf.fov = toFov(view.fov);
      }
      if (const XrCompositionLayerDepthInfoKHR* d = findDepthInfo(view)) {
        auto ds = swapchains_.find(d->subImage.swapchain);
        if (ds != swapchains_.end() && ds->second.facts().hasReleasedImage &&
            isDepthFormat(ds->second.info.format) &&
            (ds->second.info.usageFlags & XR_SWAPCHAIN_USAGE_SAMPLED_BIT)) {
          const XrSwapchainCreateInfo& di = ds->second.info;
          core::DepthRef depth;
          depth.image.image = ds->second.images[*ds->second.released];
          depth.image.format = static_cast<VkFormat>(di.format);
          depth.image.extent = {di.width, di.height};
          depth.image.arrayLayer = d->subImage.imageArrayIndex;
          depth.image.arrayLayerCount = di.arraySize;
          depth.image.rect = toRect(d->subImage.imageRect);
          depth.image.usage = vulkanUsage(di.usageFlags);
          depth.image.layout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
          depth.minDepth = d->minDepth;
          depth.maxDepth = d->maxDepth;
          depth.nearZ = d->nearZ;
          depth.farZ = d->farZ;
          vf.depth = depth;
        }
      }
    }
  }

  // One output swapchain per distinct app swapchain, acquired once this frame (runtime calls).
  struct Acquired {
    OwnedSwapchain* out;
    uint32_t index;
  };
  std::map<XrSwapchain, Acquired> acquired;
  std::optional<PassReason> failure;
  for (uint32_t v = 0; v < layer.viewCount && !failure; ++v) {
    const XrCompositionLayerProjectionView& view = layer.views[v];
    auto it = acquired.find(view.subImage.swapchain);
    if (it == acquired.end()) {
      OwnedSwapchain* out = ensureOutput(*apps[v]);
      if (!out) {
        failure = PassReason::OutputSwapchain;
        break;
      }
      uint32_t index = 0;
      if ((failure = acquireOutput(*out, &index))) break;
      it = acquired.emplace(view.subImage.swapchain, Acquired{out, index}).first;
    }
    const Acquired& acq = it->second;
    core::ImageRef& o = output.views[v];
    const XrSwapchainCreateInfo& oi = acq.out->info();
    o.image = acq.out->images()[acq.index];
    o.format = static_cast<VkFormat>(oi.format);
    o.extent = {oi.width, oi.height};
    o.arrayLayer = view.subImage.imageArrayIndex;
    o.arrayLayerCount = oi.arraySize;
    o.rect = frame.views[v].color.rect;
    o.usage = vulkanUsage(oi.usageFlags);
    o.mutableFormat = (oi.usageFlags & XR_SWAPCHAIN_USAGE_MUTABLE_FORMAT_BIT) != 0;
    o.layout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;  // after xrWaitSwapchainImage
    outputs->push_back(acq.out->handle());
  }

  if (!failure) {
    frame.headSpeedDegPerSec = headSpeed(layer, displayTime);
    if (log.enabled(LogLevel::Debug) && debugFrames_ < 10) {
      ++debugFrames_;
      const XrPosef& p = layer.views[0].pose;
      const XrFovf& f = layer.views[0].fov;
      char buf[256];
      std::snprintf(buf, sizeof buf,
                    "frame t=%lld view0 q=(%.6f %.6f %.6f %.6f) p=(%.4f %.4f %.4f) fov=(%.4f %.4f %.4f %.4f) "
                    "speed=%.3f deg/s",
                    static_cast<long long>(displayTime), p.orientation.w, p.orientation.x, p.orientation.y,
                    p.orientation.z, p.position.x, p.position.y, p.position.z, f.angleLeft, f.angleRight,
                    f.angleUp, f.angleDown, frame.headSpeedDegPerSec);
      log.log(LogLevel::Debug, buf);
    }
    std::string error;
    if (!filter_->submit(frame, output, &error)) {
      if (filter_->compiling()) {
        log.once(LogLevel::Info, "filter-compiling",
                 "the filter's pipelines are compiling in the background; frames pass through until then");
        failure = PassReason::Compiling;
      } else {
        log.once(LogLevel::Warn, "filter-submit", "filter: " + error);
        failure = PassReason::FilterError;
      }
    } else if (dumper_.wants()) {
      dumper_.dump(*vk_, frame, output, log);
    }
  }
  // Release every output image acquired this frame, filtered or not (the layer waits only on
  // its own work; the runtime orders its reads after this queue's submissions).
  for (const auto& [app, acq] : acquired) {
    const XrResult r = next().releaseSwapchainImage(acq.out->handle(), nullptr);
    if (XR_FAILED(r)) {
      log.once(LogLevel::Warn, "release", xrError("xrReleaseSwapchainImage (layer output)", r));
      failure = PassReason::XrError;
    }
  }
  if (!failure) {
    if (auto t = filter_->lastTimings()) {
      std::lock_guard lock(mutex_);
      if (t->frameIndex != stats_.lastTimingIndex) {
        stats_.lastTimingIndex = t->frameIndex;
        ++stats_.timingFrames;
        stats_.temporalMs += t->temporalMs;
        stats_.stereoMs += t->stereoMs;
        stats_.otherMs += t->otherMs;
        stats_.totalMs += t->totalMs;
      }
    }
  }
  return failure;
}

XrResult Session::locateViews(const XrViewLocateInfo* info, XrViewState* state, uint32_t capacity,
                              uint32_t* count, XrView* views) {
  const XrResult r = next().locateViews(handle_, info, state, capacity, count, views);
  if (XR_FAILED(r) || !jitter_ || !filtering_ || info == nullptr || views == nullptr || count == nullptr ||
      *count == 0 || *count > JitterTracker::kMaxViews || capacity < *count) {
    return r;
  }
  std::lock_guard lock(mutex_);
  if (viewSize_[0].width == 0 || shutDown_) return r;  // sizes known after the first filtered frame
  std::array<XrFovf, JitterTracker::kMaxViews> fovs{};
  std::array<VkExtent2D, JitterTracker::kMaxViews> sizes{};
  for (uint32_t i = 0; i < *count; ++i) {
    fovs[i] = views[i].fov;
    sizes[i] = viewSize_[i].width ? viewSize_[i] : viewSize_[0];
  }
  stats_.jitterApplied += jitterTracker_.apply(fovs.data(), sizes.data(), *count);
  for (uint32_t i = 0; i < *count; ++i) views[i].fov = fovs[i];
  return r;
}

XrResult Session::endFrame(const XrFrameEndInfo* info) {
  // Nothing of the app's frame is read before scanFrame has checked it (issue 15: layers = NULL
  // crashed here); a frame with a problem goes to the runtime exactly as the app submitted it.
  const FrameScan scan = scanFrame(info, maxLayerCount_);
  if (!scan.ok()) {
    instance_->log->once(LogLevel::Warn, "invalid-frame-" + std::string(toString(scan.problem)),
                         "xrEndFrame with " + std::string(toString(scan.problem)) +
                             ": forwarded untouched (the runtime answers it)");
  }
  if (!scan.ok() || !filtering_) {
    if (vulkanSession_) countUnfiltered(scan);
    return next().endFrame(handle_, info);
  }
  std::unique_lock frameLock(frameMutex_);
  if (!filtering_ || shutDown_) {
    frameLock.unlock();
    countUnfiltered(scan);
    return next().endFrame(handle_, info);
  }
  FrameRewrite rewrite(*info);
  std::optional<PassReason> reason;
  uint32_t viewCount = 0, matched = 0;
  std::vector<ViewUnjitter> unjitter;
  std::array<VkExtent2D, 2> sizes{};
  if (scan.projection) {
    const auto& proj = *reinterpret_cast<const XrCompositionLayerProjection*>(info->layers[*scan.projection]);
    // Views rendered with the layer's jitter are filtered onto, and submitted with, the
    // unjittered fov; any other fov (the app's own) is used as is with no jitter.
    if (jitter_ && proj.views != nullptr && proj.viewCount <= JitterTracker::kMaxViews) {
      std::lock_guard lock(mutex_);
      for (uint32_t v = 0; v < proj.viewCount; ++v) {
        const XrRect2Di& rect = proj.views[v].subImage.imageRect;
        const VkExtent2D size{static_cast<uint32_t>(std::max(rect.extent.width, 0)),
                              static_cast<uint32_t>(std::max(rect.extent.height, 0))};
        unjitter.push_back(jitterTracker_.find(v, proj.views[v].fov, size));
        matched += unjitter.back().matched ? 1 : 0;
      }
    }
    std::vector<XrSwapchain> outputs;
    reason = filterProjection(proj, info->displayTime, unjitter, &outputs);
    if (!reason) {
      std::vector<XrFovf> fovs;
      for (const ViewUnjitter& u : unjitter) fovs.push_back(u.fov);
      rewrite.replaceProjection(*scan.projection, outputs, matched > 0 ? &fovs : nullptr);
      viewCount = proj.viewCount;
      for (uint32_t v = 0; v < viewCount; ++v) {
        sizes[v] = {static_cast<uint32_t>(proj.views[v].subImage.imageRect.extent.width),
                    static_cast<uint32_t>(proj.views[v].subImage.imageRect.extent.height)};
      }
    }
  }
  frameLock.unlock();
  // The runtime call with no lock held: other threads' xrLocateViews and swapchain calls go on.
  const XrResult r = next().endFrame(handle_, rewrite.replacedCount() > 0 ? &rewrite.info() : info);

  std::lock_guard lock(mutex_);
  if (!scan.projection) {
    ++stats_.framesEmpty;
  } else if (reason) {
    passed(*reason, "projection layer left as the app submitted it");
  } else if (XR_FAILED(r)) {
    // Filtered, but the runtime refused the frame: it was never shown.
    passed(PassReason::RuntimeRejected, xrError("xrEndFrame", r));
  } else {
    for (uint32_t v = 0; v < unjitter.size(); ++v) {
      if (!unjitter[v].matched) continue;
      char buf[160];
      std::snprintf(buf, sizeof buf, "jitter: undone on submit (first: view %u, %.4f, %.4f px)", v,
                    unjitter[v].jitterPx[0], unjitter[v].jitterPx[1]);
      instance_->log->once(LogLevel::Info, "jitter-undone", buf);
      break;
    }
    stats_.jitterUndone += matched;
    stats_.jitterUnmatched += unjitter.size() - matched;
    for (uint32_t v = 0; v < viewCount; ++v) viewSize_[v] = sizes[v];
    ++stats_.framesFiltered;
    for (uint32_t v = 0; v < viewCount; ++v) ++stats_.viewsFiltered[v];
  }
  return r;
}

}  // namespace steadyxr::layer
