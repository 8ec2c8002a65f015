#include "session.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <set>
#include <sstream>
#include <utility>

namespace steadyxr::layer {
namespace {

template <typename T>
bool load(XrInstance instance, PFN_xrGetInstanceProcAddr gipa, const char* name, T* out) {
  PFN_xrVoidFunction f = nullptr;
  if (XR_FAILED(gipa(instance, name, &f)) || f == nullptr) return false;
  *out = reinterpret_cast<T>(f);
  return true;
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
  load(i, g, "xrGetSystemProperties", &d->getSystemProperties);             // maxLayerCount
  load(i, g, "xrCreateVulkanInstanceKHR", &d->createVulkanInstanceKHR);     // optional
  load(i, g, "xrConvertTimeToTimespecTimeKHR", &d->convertTimeToTimespec);  // optional
  return ok;
}

uint32_t deviceApiVersion(VkPhysicalDevice physicalDevice, VkDevice device) {
  if (physicalDevice == VK_NULL_HANDLE || device == VK_NULL_HANDLE) return VK_API_VERSION_1_0;
  // Core device commands of each version, each from a different extension, none a loader
  // trampoline (the loader hands out vkGetDeviceQueue2 whatever the version: measured on
  // Vulkan-Loader 1.3.239 and 1.4.309 with lavapipe).
  struct Level {
    uint32_t version;
    std::array<const char*, 3> commands;
  };
  constexpr Level kLevels[] = {
      {VK_API_VERSION_1_1, {"vkTrimCommandPool", "vkGetDescriptorSetLayoutSupport", "vkCmdDispatchBase"}},
      {VK_API_VERSION_1_2, {"vkGetBufferDeviceAddress", "vkCmdDrawIndirectCount", "vkResetQueryPool"}},
      {VK_API_VERSION_1_3,
       {"vkCmdSetCullMode", "vkCmdBeginRendering", "vkGetDeviceBufferMemoryRequirements"}},
  };
  uint32_t version = VK_API_VERSION_1_0;
  for (const Level& level : kLevels) {
    bool all = true;
    for (const char* c : level.commands) all = all && vkGetDeviceProcAddr(device, c) != nullptr;
    if (!all) break;
    version = level.version;
  }
  VkPhysicalDeviceProperties props{};
  vkGetPhysicalDeviceProperties(physicalDevice, &props);
  return std::min(version, VK_MAKE_API_VERSION(0, VK_API_VERSION_MAJOR(props.apiVersion),
                                               VK_API_VERSION_MINOR(props.apiVersion), 0));
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
     << " frames_warming_up=" << warmingUp << " frames_warming_up_late=" << warmingUpLate
     << " frames_empty=" << framesEmpty << " frames_disabled=" << framesDisabled
     << " history_dropped=" << historyDropped << " render_size_changes=" << renderSize.framesResized
     << " history_kept_resized=" << renderSize.historyKeptResized
     << " images_reallocated=" << renderSize.imagesReallocated << " image_memory_mib=" << std::fixed
     << std::setprecision(1) << double(imageMemoryBytes) / (1024.0 * 1024.0) << std::defaultfloat;
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

Session::Session(std::shared_ptr<InstanceState> instance, XrSession handle, XrSystemId system,
                 std::optional<XrGraphicsBindingVulkanKHR> vulkan)
    : instance_(std::move(instance)),
      handle_(handle),
      dumper_(instance_->config.dumpDir, instance_->config.dumpFrames) {
  Logger& log = *instance_->log;
  if (next().getSystemProperties != nullptr) {
    auto props = makeXr<XrSystemProperties>(XR_TYPE_SYSTEM_PROPERTIES);
    if (XR_SUCCEEDED(next().getSystemProperties(instance_->handle, system, &props)))
      maxLayerCount_ = std::clamp(props.graphicsProperties.maxLayerCount, kMinLayerLimit, kMaxLayerLimit);
  }
  if (!vulkan) {
    log.log(LogLevel::Info, "session is not a Vulkan session: passing everything through");
    return;
  }
  vulkanSession_ = true;
  try {
    setUp(*vulkan);
  } catch (const std::exception& e) {
    // The session still exists for the app: it must stay registered and pass frames through.
    log.log(LogLevel::Error, std::string("session set-up failed (") + e.what() + "): passing frames through");
    filtering_ = false;
  } catch (...) {
    log.log(LogLevel::Error, "session set-up failed: passing frames through");
    filtering_ = false;
  }
}

void Session::setUp(const XrGraphicsBindingVulkanKHR& vulkan) {
  binding_ = vulkan;
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
  Logger* log = instance_->log.get();  // outlives imu_ (the instance state outlives its sessions)
  imu_ = imu::openImuPoseSource(spec, &error, [log](const std::string& line) {
    log->log(LogLevel::Warn, "pose_source = imu: " + line);
  });
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
  h.apiVersion = instance_->vulkanApiVersion.value_or(0);
  if (!instance_->vulkanApiVersion) {  // XR_KHR_vulkan_enable (v1)
    h.apiVersion = deviceApiVersion(binding_.physicalDevice, binding_.device);
    log.log(LogLevel::Info, "XR_KHR_vulkan_enable: the app's Vulkan device runs at " +
                                std::to_string(VK_API_VERSION_MAJOR(h.apiVersion)) + "." +
                                std::to_string(VK_API_VERSION_MINOR(h.apiVersion)));
  }
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
  filterOptions.holdBackForTests = instance_->holdBackPipelinesForTests;
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
  std::map<XrSwapchain, AppSwapchain> doomed;
  XrSpace space = XR_NULL_HANDLE;
  std::string summary;
  {
    std::scoped_lock lock(frameMutex_, mutex_);
    if (shutDown_) return;
    shutDown_ = true;
    filtering_ = false;
    if (filter_) filter_->waitIdle();
    filter_.reset();  // its views of the app's and the output images go before the images
    vk_.reset();
    doomed.swap(swapchains_);
    space = std::exchange(viewSpace_, XR_NULL_HANDLE);
    if (vulkanSession_) summary = stats_.summary();
  }
  doomed.clear();  // the layer's output swapchains: destroyed through the runtime, unlocked
  if (space != XR_NULL_HANDLE) next().destroySpace(space);
  if (!summary.empty()) instance_->log->log(LogLevel::Info, summary);
}

SessionStats Session::stats() {
  std::lock_guard lock(mutex_);
  return stats_;
}

std::string Session::xrError(const char* what, XrResult r) const {
  char buf[XR_MAX_RESULT_STRING_SIZE] = {};
  if (next().resultToString == nullptr || XR_FAILED(next().resultToString(instance_->handle, r, buf))) {
    std::snprintf(buf, sizeof buf, "XrResult %d", static_cast<int>(r));
  }
  return std::string(what) + " failed: " + buf;
}

bool Session::deviceSupports(const XrSwapchainCreateInfo& info, XrSwapchainUsageFlags usage) const {
  if (!vk_) return true;  // nothing to ask: let the runtime decide
  VkImageFormatProperties props{};
  const VkImageCreateFlags flags =
      (usage & XR_SWAPCHAIN_USAGE_MUTABLE_FORMAT_BIT) ? VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT : 0;
  const VkResult r = vkGetPhysicalDeviceImageFormatProperties(
      vk_->physicalDevice(), static_cast<VkFormat>(info.format), VK_IMAGE_TYPE_2D, VK_IMAGE_TILING_OPTIMAL,
      vulkanUsage(usage), flags, &props);
  return r == VK_SUCCESS && info.arraySize <= props.maxArrayLayers && info.width <= props.maxExtent.width &&
         info.height <= props.maxExtent.height;
}

XrResult Session::createSwapchain(const XrSwapchainCreateInfo* info, XrSwapchain* swapchain) {
  if (!filtering_ || info == nullptr || swapchain == nullptr)
    return next().createSwapchain(handle_, info, swapchain);
  // SAMPLED is added only where the device can sample the image as the app asked for it.
  // Where it cannot (the app's own usage, format or size is unsupported), the request goes to
  // the runtime exactly as the app made it, once, and the runtime's answer is the app's.
  // dump_frames > 0 also reads the app's images back (a copy needs TRANSFER_SRC usage).
  const XrSwapchainUsageFlags wanted =
      appSwapchainUsage(info->usageFlags) |
      (instance_->config.dumpFrames > 0 ? XR_SWAPCHAIN_USAGE_TRANSFER_SRC_BIT : 0);
  const bool addSampled =
      isReadableSwapchain(*info) && wanted != info->usageFlags && deviceSupports(*info, wanted);
  XrSwapchainCreateInfo ours = *info;
  if (addSampled) ours.usageFlags = wanted;
  XrResult r = next().createSwapchain(handle_, &ours, swapchain);
  if (r == XR_ERROR_FEATURE_UNSUPPORTED && addSampled) {
    // The device can sample it, the runtime still refuses the added bit (its own limits).
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
    if (!isReadableSwapchain(*info) || !(ours.usageFlags & XR_SWAPCHAIN_USAGE_SAMPLED_BIT)) {
      s.info.format = 0;  // not readable by the filter: makes checkProjection pass it through
    } else if (ours.usageFlags & XR_SWAPCHAIN_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT) {
      appHasDepthSwapchain_ = true;
    }
  }
  return r;
}

XrResult Session::destroySwapchain(XrSwapchain swapchain) {
  std::optional<AppSwapchain> doomed;
  {
    std::scoped_lock lock(frameMutex_, mutex_);  // no filter work may read its images after this
    if (auto it = swapchains_.find(swapchain); it != swapchains_.end()) {
      if (filter_) {
        filter_->waitIdle();  // in-flight filter work may still read these images
        for (VkImage img : it->second.images) filter_->forgetImage(img);
        if (it->second.output) {
          for (VkImage img : it->second.output->images()) filter_->forgetImage(img);
        }
      }
      doomed = std::move(it->second);
      swapchains_.erase(it);
    }
  }
  doomed.reset();  // the layer's output swapchain goes through the runtime, unlocked
  return next().destroySwapchain(swapchain);
}

XrResult Session::enumerateImages(XrSwapchain swapchain, uint32_t capacity, uint32_t* count,
                                  XrSwapchainImageBaseHeader* images) {
  const XrResult r = next().enumerateSwapchainImages(swapchain, capacity, count, images);
  if (XR_SUCCEEDED(r) && filtering_ && images != nullptr && capacity > 0 && count != nullptr &&
      images->type == XR_TYPE_SWAPCHAIN_IMAGE_VULKAN_KHR) {
    const uint32_t n = std::min(*count, capacity);
    std::lock_guard lock(mutex_);
    if (auto it = swapchains_.find(swapchain); it != swapchains_.end()) {
      const auto* vkImages = reinterpret_cast<const XrSwapchainImageVulkanKHR*>(images);
      it->second.images.assign(n, VK_NULL_HANDLE);
      for (uint32_t i = 0; i < n; ++i) it->second.images[i] = vkImages[i].image;
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

// The layer's sub-pixel jitter goes into the fov the app renders with; Session::matchJitter
// (session_frame.cpp) recognises it in xrEndFrame and undoes it.
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

}  // namespace steadyxr::layer
