#include "session.h"

#include "steadyxr/core/view_math.h"

#include <glm/gtc/quaternion.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <sstream>

namespace steadyxr::layer {
namespace {

constexpr XrDuration kOutputWaitNs = 1'000'000'000;  // bounded: never hang the frame loop

template <typename T>
bool load(XrInstance instance, PFN_xrGetInstanceProcAddr gipa, const char* name, T* out) {
  PFN_xrVoidFunction f = nullptr;
  if (XR_FAILED(gipa(instance, name, &f)) || f == nullptr) return false;
  *out = reinterpret_cast<T>(f);
  return true;
}

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

bool loadDispatch(XrInstance i, PFN_xrGetInstanceProcAddr g, Dispatch* d) {
  d->getInstanceProcAddr = g;
  const bool ok = load(i, g, "xrDestroyInstance", &d->destroyInstance) &&
                  load(i, g, "xrCreateSession", &d->createSession) &&
                  load(i, g, "xrDestroySession", &d->destroySession) &&
                  load(i, g, "xrCreateSwapchain", &d->createSwapchain) &&
                  load(i, g, "xrDestroySwapchain", &d->destroySwapchain) &&
                  load(i, g, "xrEnumerateSwapchainImages", &d->enumerateSwapchainImages) &&
                  load(i, g, "xrAcquireSwapchainImage", &d->acquireSwapchainImage) &&
                  load(i, g, "xrWaitSwapchainImage", &d->waitSwapchainImage) &&
                  load(i, g, "xrReleaseSwapchainImage", &d->releaseSwapchainImage) &&
                  load(i, g, "xrEnumerateSwapchainFormats", &d->enumerateSwapchainFormats) &&
                  load(i, g, "xrLocateViews", &d->locateViews) && load(i, g, "xrEndFrame", &d->endFrame) &&
                  load(i, g, "xrCreateReferenceSpace", &d->createReferenceSpace) &&
                  load(i, g, "xrDestroySpace", &d->destroySpace) &&
                  load(i, g, "xrLocateSpace", &d->locateSpace) &&
                  load(i, g, "xrResultToString", &d->resultToString);
  load(i, g, "xrCreateVulkanInstanceKHR", &d->createVulkanInstanceKHR);     // optional
  load(i, g, "xrConvertTimeToTimespecTimeKHR", &d->convertTimeToTimespec);  // optional
  return ok;
}

SwapchainFacts AppSwapchain::facts() const {
  SwapchainFacts f;
  f.format = info.format;
  f.width = info.width;
  f.height = info.height;
  f.arraySize = info.arraySize;
  f.usage = info.usageFlags;
  f.hasReleasedImage = released.has_value() && *released < images.size();
  f.imagesKnown = !images.empty();
  return f;
}

std::string SessionStats::summary() const {
  std::ostringstream os;
  // Frames that waited for the pipelines are counted apart: passing them through is the plan,
  // not a failure.
  const uint64_t warmingUp = passed[static_cast<size_t>(PassReason::Compiling)];
  uint64_t passedTotal = 0;
  for (uint64_t n : passed) passedTotal += n;
  passedTotal -= warmingUp;
  os << "session summary: frames_filtered=" << framesFiltered << " left=" << viewsFiltered[0]
     << " right=" << viewsFiltered[1] << " frames_passed_through=" << passedTotal
     << " frames_warming_up=" << warmingUp << " frames_empty=" << framesEmpty
     << " frames_disabled=" << framesDisabled;
  if (passedTotal > 0) {
    os << " (";
    bool first = true;
    for (size_t r = 0; r < passed.size(); ++r) {
      if (passed[r] == 0 || r == static_cast<size_t>(PassReason::Compiling)) continue;
      os << (first ? "" : ", ") << toString(static_cast<PassReason>(r)) << "=" << passed[r];
      first = false;
    }
    os << ")";
  }
  char buf[160];
  if (timingFrames > 0) {
    const double n = static_cast<double>(timingFrames);
    std::snprintf(buf, sizeof buf,
                  " gpu_ms_mean: temporal=%.3f stereo=%.3f other=%.3f total=%.3f (%llu frames)",
                  temporalMs / n, stereoMs / n, otherMs / n, totalMs / n,
                  static_cast<unsigned long long>(timingFrames));
  } else {
    std::snprintf(buf, sizeof buf, " gpu_ms_mean: n/a");
  }
  os << buf;
  if (imuFrames + imuFallbackFrames > 0)
    os << " imu_frames=" << imuFrames << " imu_fallback=" << imuFallbackFrames;
  if (jitter) {
    os << " jitter_views: applied=" << jitterApplied << " undone=" << jitterUndone
       << " unmatched=" << jitterUnmatched;
  }
  return os.str();
}

Session::Session(std::shared_ptr<InstanceState> instance, XrSession handle,
                 std::optional<XrGraphicsBindingVulkanKHR> vulkan)
    : instance_(std::move(instance)),
      handle_(handle),
      dumper_(instance_->config.dumpDir, instance_->config.dumpFrames) {
  Logger& log = *instance_->log;
  if (!vulkan) {
    log.log(LogLevel::Info, "session is not a Vulkan session: passing everything through");
    return;
  }
  vulkanSession_ = true;
  binding_ = *vulkan;
  binding_.next = nullptr;
  filtering_ = initFilter();
  if (!filtering_) return;
  if (instance_->config.poseSource == PoseSourceKind::Imu) openImu();
  auto rci = makeXr<XrReferenceSpaceCreateInfo>(XR_TYPE_REFERENCE_SPACE_CREATE_INFO);
  rci.referenceSpaceType = XR_REFERENCE_SPACE_TYPE_VIEW;
  rci.poseInReferenceSpace.orientation.w = 1.0f;
  if (XR_FAILED(next().createReferenceSpace(handle_, &rci, &viewSpace_))) viewSpace_ = XR_NULL_HANDLE;
}

Session::~Session() {
  shutdown();
}

void Session::openImu() {
  const std::string& device = instance_->config.imuDevice;
  char defaultSpec[32];
  std::snprintf(defaultSpec, sizeof defaultSpec, "hid:%04x:%04x", imu::hid::kVendorId, imu::hid::kProductId);
  const std::string spec = device == "auto" ? std::string(defaultSpec) : device;
  std::string error;
  imu_ = imu::openImuPoseSource(spec, &error);
  if (!imu_) {
    instance_->log->log(LogLevel::Warn, "pose_source = imu: cannot open '" + spec + "' (" + error +
                                            "); head speed comes from the runtime's poses");
  } else {
    instance_->log->log(LogLevel::Info, "pose_source = imu: reading " + spec);
  }
}

bool Session::initFilter() {
  Logger& log = *instance_->log;
  const Config& cfg = instance_->config;
  core::BorrowedHandles h;
  h.instance = binding_.instance;
  h.physicalDevice = binding_.physicalDevice;
  h.device = binding_.device;
  h.queueFamilyIndex = binding_.queueFamilyIndex;
  h.queueIndex = binding_.queueIndex;
  h.apiVersion = instance_->vulkanApiVersion;
  std::string error;
  vk_ = core::VulkanContext::borrow(h, &error);
  if (!vk_) {
    log.log(LogLevel::Error, "cannot use the app's Vulkan device (" + error + "): passing frames through");
    return false;
  }
  std::optional<core::Params> params = core::applyMethodName(cfg.method, cfg.params);
  if (!params) {
    log.log(LogLevel::Warn, "config: bad value '" + cfg.method + "' for key 'method'; using the default");
    params = core::applyMethodName("default", cfg.params);
  }
  core::Params sanitized = params.value_or(cfg.params);
  if (const std::string msg = core::validate(sanitized, &sanitized); !msg.empty()) {
    log.log(LogLevel::Warn, "config: " + msg + "; using the defaults for the bad fields");
  }
  sanitized.jitteredInput = cfg.jitter && undoesJitter(sanitized.temporal);
  // Pipelines compile on worker threads: the app's first frames pass through instead of stalling.
  core::FilterOptions filterOptions;
  filterOptions.compileInBackground = true;
  filter_ = core::Filter::create(*vk_, sanitized, &error, filterOptions);
  if (!filter_) {
    log.log(LogLevel::Error, "cannot create the filter (" + error + "): passing frames through");
    vk_.reset();
    return false;
  }
  log.log(LogLevel::Info, "filtering with method '" + core::methodName(sanitized) + "' on " +
                              std::string(vk_->properties().deviceName));
  if (cfg.jitter) {
    jitter_ = undoesJitter(sanitized.temporal);
    stats_.jitter = jitter_;
    if (!jitter_) {
      // Nothing would un-jitter the image: the jitter would only shake it.
      log.log(LogLevel::Warn, "jitter = 1 ignored: method '" + core::methodName(sanitized) +
                                  "' has no temporal pass to undo it");
    } else {
      log.log(LogLevel::Info, "jitter: injecting a Halton(2,3) sub-pixel jitter into xrLocateViews' fov");
    }
  }
  return true;
}

void Session::shutdown() {
  std::lock_guard lock(mutex_);
  if (shutDown_) return;
  shutDown_ = true;
  if (filter_) filter_->waitIdle();
  swapchains_.clear();  // destroys the layer's output swapchains
  if (viewSpace_ != XR_NULL_HANDLE) next().destroySpace(viewSpace_);
  viewSpace_ = XR_NULL_HANDLE;
  filter_.reset();
  vk_.reset();
  if (vulkanSession_) instance_->log->log(LogLevel::Info, stats_.summary());
}

std::string Session::xrError(const char* what, XrResult r) const {
  char buf[XR_MAX_RESULT_STRING_SIZE] = {};
  if (next().resultToString == nullptr || XR_FAILED(next().resultToString(instance_->handle, r, buf))) {
    std::snprintf(buf, sizeof buf, "XrResult %d", static_cast<int>(r));
  }
  return std::string(what) + " failed: " + buf;
}

XrResult Session::createSwapchain(const XrSwapchainCreateInfo* info, XrSwapchain* swapchain) {
  if (!filtering_ || info == nullptr) return next().createSwapchain(handle_, info, swapchain);
  if (!isReadableSwapchain(*info)) {
    const XrResult r = next().createSwapchain(handle_, info, swapchain);
    if (XR_SUCCEEDED(r)) {
      std::lock_guard lock(mutex_);
      AppSwapchain& s = swapchains_[*swapchain];
      s.info = *info;
      s.info.next = nullptr;
      s.info.format = 0;  // makes checkProjection pass its frames through (unsupported format)
    }
    return r;
  }
  XrSwapchainCreateInfo ours = *info;
  ours.usageFlags = appSwapchainUsage(info->usageFlags);
  XrResult r = next().createSwapchain(handle_, &ours, swapchain);
  if (XR_FAILED(r) && ours.usageFlags != info->usageFlags) {
    instance_->log->once(LogLevel::Warn, "sampled-usage",
                         "the runtime refused SAMPLED usage on an app swapchain: its frames pass through");
    ours = *info;
    r = next().createSwapchain(handle_, info, swapchain);
  }
  if (XR_SUCCEEDED(r)) {
    std::lock_guard lock(mutex_);
    AppSwapchain& s = swapchains_[*swapchain];
    s.info = ours;
    s.info.next = nullptr;
    if (ours.usageFlags == info->usageFlags && !(info->usageFlags & XR_SWAPCHAIN_USAGE_SAMPLED_BIT)) {
      s.info.format = 0;  // not readable by the filter: makes checkProjection pass it through
    }
  }
  return r;
}

XrResult Session::destroySwapchain(XrSwapchain swapchain) {
  {
    std::lock_guard lock(mutex_);
    if (auto it = swapchains_.find(swapchain); it != swapchains_.end()) {
      if (filter_) {
        filter_->waitIdle();  // in-flight filter work may still read these images
        for (VkImage img : it->second.images) filter_->forgetImage(img);
        if (it->second.output) {
          for (VkImage img : it->second.output->images()) filter_->forgetImage(img);
        }
      }
      swapchains_.erase(it);
    }
  }
  return next().destroySwapchain(swapchain);
}

XrResult Session::enumerateImages(XrSwapchain swapchain, uint32_t capacity, uint32_t* count,
                                  XrSwapchainImageBaseHeader* images) {
  const XrResult r = next().enumerateSwapchainImages(swapchain, capacity, count, images);
  if (XR_SUCCEEDED(r) && filtering_ && images != nullptr && capacity > 0 && count != nullptr &&
      images->type == XR_TYPE_SWAPCHAIN_IMAGE_VULKAN_KHR) {
    std::lock_guard lock(mutex_);
    if (auto it = swapchains_.find(swapchain); it != swapchains_.end()) {
      const auto* vkImages = reinterpret_cast<const XrSwapchainImageVulkanKHR*>(images);
      it->second.images.assign(*count, VK_NULL_HANDLE);
      for (uint32_t i = 0; i < *count; ++i) it->second.images[i] = vkImages[i].image;
    }
  }
  return r;
}

XrResult Session::acquire(XrSwapchain swapchain, const XrSwapchainImageAcquireInfo* info, uint32_t* index) {
  const XrResult r = next().acquireSwapchainImage(swapchain, info, index);
  if (XR_SUCCEEDED(r) && filtering_ && index != nullptr) {
    std::lock_guard lock(mutex_);
    if (auto it = swapchains_.find(swapchain); it != swapchains_.end()) it->second.acquired.push_back(*index);
  }
  return r;
}

XrResult Session::release(XrSwapchain swapchain, const XrSwapchainImageReleaseInfo* info) {
  const XrResult r = next().releaseSwapchainImage(swapchain, info);
  if (XR_SUCCEEDED(r) && filtering_) {
    std::lock_guard lock(mutex_);
    if (auto it = swapchains_.find(swapchain); it != swapchains_.end() && !it->second.acquired.empty()) {
      it->second.released = it->second.acquired.front();
      it->second.acquired.pop_front();
    }
  }
  return r;
}

void Session::countUnfiltered(const XrFrameEndInfo& info) {
  std::lock_guard lock(mutex_);
  for (uint32_t i = 0; i < info.layerCount; ++i) {
    if (info.layers[i] != nullptr && info.layers[i]->type == XR_TYPE_COMPOSITION_LAYER_PROJECTION) {
      ++(filtering_ ? stats_.framesDisabled : stats_.passed[static_cast<size_t>(failedReason_)]);
      return;
    }
  }
  ++stats_.framesEmpty;
}

void Session::passed(PassReason reason, const std::string& detail) {
  ++stats_.passed[static_cast<size_t>(reason)];
  if (reason == PassReason::Compiling) return;  // expected for the first frames: logged once at info
  instance_->log->once(LogLevel::Warn, "pass-" + std::string(toString(reason)),
                       "passing frames through (" + std::string(toString(reason)) + "): " + detail);
}

OwnedSwapchain* Session::ensureOutput(AppSwapchain& app) {
  if (app.output) return app.output.get();
  const XrSwapchainCreateInfo info = outputSwapchainInfo(app.info, mutableFormat_);
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
  for (const auto& i : imgs) images.push_back(i.image);
  app.output = std::make_unique<OwnedSwapchain>(next(), handle, info, std::move(images));
  return app.output.get();
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
      ++stats_.imuFrames;
      return s->headSpeedDegPerSec;
    }
    ++stats_.imuFallbackFrames;
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

std::optional<PassReason> Session::filterProjection(const XrCompositionLayerProjection& layer,
                                                    int64_t displayTime,
                                                    const std::vector<ViewUnjitter>& unjitter,
                                                    std::vector<XrSwapchain>* outputs) {
  Logger& log = *instance_->log;
  const auto lookup = [this](XrSwapchain s) -> std::optional<SwapchainFacts> {
    auto it = swapchains_.find(s);
    if (it == swapchains_.end()) return std::nullopt;
    return it->second.facts();
  };
  if (auto reason = checkProjection(layer, lookup)) return reason;

  // One output swapchain per distinct app swapchain, acquired once this frame.
  struct Acquired {
    OwnedSwapchain* out;
    uint32_t index;
  };
  std::map<XrSwapchain, Acquired> acquired;
  core::StereoFrame frame;
  core::StereoOutput output;
  frame.viewCount = layer.viewCount;
  frame.displayTimeNs = displayTime;
  std::optional<PassReason> failure;
  for (uint32_t v = 0; v < layer.viewCount && !failure; ++v) {
    const XrCompositionLayerProjectionView& view = layer.views[v];
    AppSwapchain& app = swapchains_.at(view.subImage.swapchain);
    auto it = acquired.find(view.subImage.swapchain);
    if (it == acquired.end()) {
      OwnedSwapchain* out = ensureOutput(app);
      if (!out) {
        failure = PassReason::OutputSwapchain;
        break;
      }
      uint32_t index = 0;
      XrResult r = next().acquireSwapchainImage(out->handle(), nullptr, &index);
      if (XR_FAILED(r)) {
        log.once(LogLevel::Warn, "acquire", xrError("xrAcquireSwapchainImage (layer output)", r));
        failure = PassReason::XrError;
        break;
      }
      auto wi = makeXr<XrSwapchainImageWaitInfo>(XR_TYPE_SWAPCHAIN_IMAGE_WAIT_INFO);
      wi.timeout = kOutputWaitNs;
      r = next().waitSwapchainImage(out->handle(), &wi);
      if (r != XR_SUCCESS) {
        // An image that was not waited for cannot be released: stop filtering this session.
        log.log(LogLevel::Error, xrError("xrWaitSwapchainImage (layer output)", r) + "; filtering stops");
        filtering_ = false;
        failedReason_ = PassReason::XrError;
        failure = PassReason::XrError;
        break;
      }
      it = acquired.emplace(view.subImage.swapchain, Acquired{out, index}).first;
    }
    const Acquired& acq = it->second;
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
    core::ImageRef& o = output.views[v];
    const XrSwapchainCreateInfo& oi = acq.out->info();
    o.image = acq.out->images()[acq.index];
    o.format = static_cast<VkFormat>(oi.format);
    o.extent = {oi.width, oi.height};
    o.arrayLayer = view.subImage.imageArrayIndex;
    o.arrayLayerCount = oi.arraySize;
    o.rect = vf.color.rect;
    o.usage = vulkanUsage(oi.usageFlags);
    o.mutableFormat = (oi.usageFlags & XR_SWAPCHAIN_USAGE_MUTABLE_FORMAT_BIT) != 0;
    o.layout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;  // after xrWaitSwapchainImage
    outputs->push_back(acq.out->handle());
  }

  if (!failure) {
    frame.headSpeedDegPerSec = headSpeed(layer, displayTime);
    if (log.enabled(LogLevel::Debug) && stats_.framesFiltered < 10) {
      const XrPosef& p = layer.views[0].pose;
      const XrFovf& f = layer.views[0].fov;
      char buf[256];
      std::snprintf(
          buf, sizeof buf,
          "frame %llu t=%lld view0 q=(%.6f %.6f %.6f %.6f) p=(%.4f %.4f %.4f) fov=(%.4f %.4f %.4f %.4f) "
          "speed=%.3f deg/s",
          static_cast<unsigned long long>(stats_.framesFiltered), static_cast<long long>(displayTime),
          p.orientation.w, p.orientation.x, p.orientation.y, p.orientation.z, p.position.x, p.position.y,
          p.position.z, f.angleLeft, f.angleRight, f.angleUp, f.angleDown, frame.headSpeedDegPerSec);
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
    if (auto t = filter_->lastTimings(); t && t->frameIndex != stats_.lastTimingIndex) {
      stats_.lastTimingIndex = t->frameIndex;
      ++stats_.timingFrames;
      stats_.temporalMs += t->temporalMs;
      stats_.stereoMs += t->stereoMs;
      stats_.otherMs += t->otherMs;
      stats_.totalMs += t->totalMs;
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
  applyLiveConfig();  // config file edits: enabled, method, pass parameters
  publishStatus();    // about once a second
  if (info == nullptr || !filtering_ || !liveEnabled_) {
    if (info != nullptr && vulkanSession_) countUnfiltered(*info);
    return next().endFrame(handle_, info);
  }
  std::unique_lock lock(mutex_);
  if (!filtering_ || shutDown_) {
    lock.unlock();
    return next().endFrame(handle_, info);
  }
  FrameRewrite rewrite(*info);
  bool sawProjection = false;
  std::optional<PassReason> reason;
  for (uint32_t i = 0; i < info->layerCount; ++i) {
    const XrCompositionLayerBaseHeader* l = info->layers[i];
    if (l == nullptr || l->type != XR_TYPE_COMPOSITION_LAYER_PROJECTION) continue;  // other types: as is
    if (sawProjection) continue;  // one filter history: only the first projection layer is filtered
    sawProjection = true;
    const auto& proj = *reinterpret_cast<const XrCompositionLayerProjection*>(l);
    // Views rendered with the layer's jitter are filtered onto, and submitted with, the
    // unjittered fov; any other fov (the app's own) is used as is with no jitter.
    std::vector<ViewUnjitter> unjitter;
    uint32_t matched = 0;
    if (jitter_ && proj.views != nullptr && proj.viewCount <= JitterTracker::kMaxViews) {
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
      rewrite.replaceProjection(i, outputs, matched > 0 ? &fovs : nullptr);
      stats_.jitterUndone += matched;
      for (uint32_t v = 0; v < unjitter.size(); ++v) {
        if (!unjitter[v].matched) continue;
        char buf[160];
        std::snprintf(buf, sizeof buf, "jitter: undone on submit (first: view %u, %.4f, %.4f px)", v,
                      unjitter[v].jitterPx[0], unjitter[v].jitterPx[1]);
        instance_->log->once(LogLevel::Info, "jitter-undone", buf);
        break;
      }
      stats_.jitterUnmatched += unjitter.size() - matched;
      for (uint32_t v = 0; v < proj.viewCount && v < 2; ++v) {
        viewSize_[v] = {static_cast<uint32_t>(proj.views[v].subImage.imageRect.extent.width),
                        static_cast<uint32_t>(proj.views[v].subImage.imageRect.extent.height)};
      }
      ++stats_.framesFiltered;
      for (uint32_t v = 0; v < proj.viewCount; ++v) ++stats_.viewsFiltered[v];
    }
  }
  if (!sawProjection) {
    ++stats_.framesEmpty;
  } else if (reason) {
    passed(*reason, "projection layer left as the app submitted it");
  }
  lock.unlock();
  return next().endFrame(handle_, rewrite.replacedCount() > 0 ? &rewrite.info() : info);
}

}  // namespace steadyxr::layer
