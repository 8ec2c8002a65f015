// Per-instance and per-session state of the layer, and the one registry that maps OpenXR
// handles to them (the layer's only global mutable state).
#pragma once

#include "config.h"
#include "config_watch.h"
#include "dump.h"
#include "history_continuity.h"
#include "log.h"
#include "rewrite.h"
#include "status_file.h"
#include "steadyxr/core/filter.h"
#include "steadyxr/core/vulkan_context.h"
#include "steadyxr/imu/imu_pose_source.h"

#include <array>
#include <atomic>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace steadyxr::layer {

inline constexpr char kLayerName[] = "XR_APILAYER_STEADYXR_head_taa";

// Functions of the next layer (or runtime).
struct Dispatch {
  PFN_xrGetInstanceProcAddr getInstanceProcAddr = nullptr;
  PFN_xrDestroyInstance destroyInstance = nullptr;
  PFN_xrCreateSession createSession = nullptr;
  PFN_xrDestroySession destroySession = nullptr;
  PFN_xrCreateSwapchain createSwapchain = nullptr;
  PFN_xrDestroySwapchain destroySwapchain = nullptr;
  PFN_xrEnumerateSwapchainImages enumerateSwapchainImages = nullptr;
  PFN_xrAcquireSwapchainImage acquireSwapchainImage = nullptr;
  PFN_xrWaitSwapchainImage waitSwapchainImage = nullptr;
  PFN_xrReleaseSwapchainImage releaseSwapchainImage = nullptr;
  PFN_xrEnumerateSwapchainFormats enumerateSwapchainFormats = nullptr;
  PFN_xrLocateViews locateViews = nullptr;
  PFN_xrEndFrame endFrame = nullptr;
  PFN_xrCreateReferenceSpace createReferenceSpace = nullptr;
  PFN_xrDestroySpace destroySpace = nullptr;
  PFN_xrLocateSpace locateSpace = nullptr;
  PFN_xrResultToString resultToString = nullptr;
  PFN_xrGetSystemProperties getSystemProperties = nullptr;             // maxLayerCount (optional)
  PFN_xrCreateVulkanInstanceKHR createVulkanInstanceKHR = nullptr;     // XR_KHR_vulkan_enable2 only
  PFN_xrConvertTimeToTimespecTimeKHR convertTimeToTimespec = nullptr;  // XR_KHR_convert_timespec_time
};
bool loadDispatch(XrInstance instance, PFN_xrGetInstanceProcAddr gipa, Dispatch* out);

// The effective Vulkan version of an app's device, major.minor (XR_KHR_vulkan_enable, v1: the
// app created its VkInstance itself, so the layer never saw its VkApplicationInfo::apiVersion;
// Proton/DXVK ask for 1.3). The driver resolves a core device command through
// vkGetDeviceProcAddr only when the device's effective version (the lower of the instance's
// requested apiVersion and the physical device's) has it (Vulkan spec, vkGetDeviceProcAddr);
// probing three commands per version, from three different extensions, keeps an app's enabled
// extension from passing for the version.
uint32_t deviceApiVersion(VkPhysicalDevice physicalDevice, VkDevice device);

struct InstanceState {
  XrInstance handle = XR_NULL_HANDLE;
  Dispatch next;
  Config config;
  std::unique_ptr<Logger> log;
  std::string applicationName;
  // From xrCreateVulkanInstanceKHR (XR_KHR_vulkan_enable2); unset on the v1 path, where the
  // session reads the device's effective version itself (deviceApiVersion).
  std::optional<uint32_t> vulkanApiVersion;
  std::unique_ptr<LiveConfig> live;    // edits of the config file while the app runs
  std::unique_ptr<StatusFile> status;  // $XDG_RUNTIME_DIR/steadyxr/<pid>-<n>.status
  // For the layer's tests only (the layer never sets it): core::FilterOptions::holdBackForTests.
  std::function<bool(const core::PipelineDescription&)> holdBackPipelinesForTests;
};

// A swapchain the layer owns (its output images). Destroys itself through the next layer.
class OwnedSwapchain {
 public:
  OwnedSwapchain(const Dispatch& next, XrSwapchain handle, const XrSwapchainCreateInfo& info,
                 std::vector<VkImage> images)
      : next_(&next), handle_(handle), info_(info), images_(std::move(images)) {}
  ~OwnedSwapchain() {
    if (handle_ != XR_NULL_HANDLE) next_->destroySwapchain(handle_);
  }
  OwnedSwapchain(const OwnedSwapchain&) = delete;
  OwnedSwapchain& operator=(const OwnedSwapchain&) = delete;
  XrSwapchain handle() const { return handle_; }
  const XrSwapchainCreateInfo& info() const { return info_; }
  const std::vector<VkImage>& images() const { return images_; }
  // An image acquired whose wait has not succeeded yet (a timeout): waited for again on the
  // next frame instead of acquiring another (the spec allows one wait per acquire, in order).
  std::optional<uint32_t> unwaited;

 private:
  const Dispatch* next_;
  XrSwapchain handle_;
  XrSwapchainCreateInfo info_;
  std::vector<VkImage> images_;
};

struct AppSwapchain {
  XrSwapchainCreateInfo info{};  // as created (with the layer's added usage)
  std::vector<VkImage> images;
  std::deque<uint32_t> acquired;     // acquired, not yet released (FIFO per the spec)
  std::optional<uint32_t> released;  // the newest released image: what xrEndFrame shows
  std::unique_ptr<OwnedSwapchain> output;
  SwapchainFacts facts() const;
};

struct SessionStats {
  uint64_t framesFiltered = 0;
  std::array<uint64_t, 2> viewsFiltered{};
  uint64_t framesEmpty = 0;     // no projection layer submitted (not rendering)
  uint64_t framesDisabled = 0;  // passed through while `enabled = 0` (live switch)
  std::array<uint64_t, static_cast<size_t>(PassReason::Count)> passed{};
  uint64_t timingFrames = 0;
  double temporalMs = 0, stereoMs = 0, otherMs = 0, totalMs = 0;
  uint64_t lastTimingIndex = UINT64_MAX;
  uint64_t imuFrames = 0;          // frames whose head speed came from the IMU
  uint64_t imuFallbackFrames = 0;  // pose_source = imu, but no IMU sample near the display time
  bool jitter = false;             // jitter = 1 with a temporal method: the counters below apply
  uint64_t jitterApplied = 0;      // views jittered in xrLocateViews
  uint64_t jitterUndone = 0;       // filtered views submitted with the jitter undone
  uint64_t jitterUnmatched = 0;    // filtered views whose fov was not one the layer jittered
  uint64_t historyDropped = 0;     // filtered frames that started without the history (HistoryContinuity)
  // Of passed[Compiling], those after the first filtered frame: a method switched live, depth that the
  // app starts to submit. Zero in a session that changes neither: filtering, once begun, goes on.
  uint64_t warmingUpLate = 0;
  core::RenderSizeCounters renderSize;  // the app's changes of render size (dynamic resolution)
  uint64_t imageMemoryBytes = 0;        // the filter's own images (core::Filter::imageMemoryBytes)
  std::string summary() const;
};

// Threads: an app may call xrLocateViews, swapchain functions and xrEndFrame from different
// threads. `mutex_` guards the layer's bookkeeping and is never held across a call into the
// runtime; `frameMutex_` serialises the layer's own frame work (the filter, its output
// swapchains, the dump), which only xrEndFrame, xrDestroySwapchain and shutdown take
// (in that order before mutex_).
class Session {
 public:
  // Never throws: anything that fails during set-up leaves a pass-through session.
  Session(std::shared_ptr<InstanceState> instance, XrSession handle, XrSystemId system,
          std::optional<XrGraphicsBindingVulkanKHR> vulkan);
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  const Dispatch& next() const { return instance_->next; }
  XrSession handle() const { return handle_; }
  bool filtering() const { return filtering_; }
  SessionStats stats();

  XrResult createSwapchain(const XrSwapchainCreateInfo* info, XrSwapchain* swapchain);
  XrResult destroySwapchain(XrSwapchain swapchain);
  XrResult enumerateImages(XrSwapchain swapchain, uint32_t capacity, uint32_t* count,
                           XrSwapchainImageBaseHeader* images);
  XrResult acquire(XrSwapchain swapchain, const XrSwapchainImageAcquireInfo* info, uint32_t* index);
  XrResult release(XrSwapchain swapchain, const XrSwapchainImageReleaseInfo* info);
  XrResult endFrame(const XrFrameEndInfo* info);
  XrResult locateViews(const XrViewLocateInfo* info, XrViewState* state, uint32_t capacity, uint32_t* count,
                       XrView* views);
  // Waits for the GPU, logs the summary and destroys what the layer created in the session.
  void shutdown();

 private:
  void setUp(const XrGraphicsBindingVulkanKHR& vulkan);
  bool initFilter();
  bool deviceSupports(const XrSwapchainCreateInfo& info, XrSwapchainUsageFlags usage) const;
  void openImu();
  // The steps of endFrame, in the order it runs them (session_frame.cpp). FrameWork is what one
  // frame carries from step to step.
  struct FrameWork;
  FrameScan scanAppFrame(const XrFrameEndInfo* info);
  XrResult passThrough(const FrameScan& scan, const XrFrameEndInfo* info);
  void matchJitter(FrameWork& work);
  std::optional<PassReason> chooseViews(FrameWork& work);
  std::optional<core::DepthRef> appDepth(const XrCompositionLayerDepthInfoKHR& depthInfo) const;
  std::optional<PassReason> acquireOutputs(FrameWork& work);
  float headSpeed(const XrCompositionLayerProjection& layer, int64_t displayTime);
  std::optional<PassReason> runFilter(FrameWork& work);
  void releaseOutputs(FrameWork& work);
  void recordTimings();
  void rewriteProjection(FrameWork& work);
  void countFrame(const FrameWork& work, XrResult runtimeResult);
  void countUnfiltered(const FrameScan& scan);
  void passed(PassReason reason, const std::string& detail);
  // The layer's output swapchains, and app images it has not seen yet (session_output.cpp).
  OwnedSwapchain* ensureOutput(AppSwapchain& app);
  void ensureImages(const XrCompositionLayerProjection& layer);
  std::optional<PassReason> acquireOutput(OwnedSwapchain& out, uint32_t* index);
  std::string xrError(const char* what, XrResult r) const;
  // Live settings and status (session_live.cpp).
  void applyLiveConfig();
  void publishStatus();
  std::string statusText() const;

  std::shared_ptr<InstanceState> instance_;
  XrSession handle_;
  std::atomic<bool> filtering_ = false;  // read unlocked on the fast pass-through path
  // The app made a depth swapchain the filter can read: its frames may start or stop giving depth
  // (core::Filter::setDepthMayChange).
  std::atomic<bool> appHasDepthSwapchain_ = false;
  bool vulkanSession_ = false;
  PassReason failedReason_ = PassReason::FilterError;  // why filtering_ is off in a Vulkan session
  bool shutDown_ = false;
  XrGraphicsBindingVulkanKHR binding_{};
  std::mutex frameMutex_;
  std::mutex mutex_;
  uint32_t maxLayerCount_ = kMinLayerLimit;
  std::unique_ptr<core::VulkanContext> vk_;
  std::unique_ptr<core::Filter> filter_;  // declared after vk_: destroyed first
  std::map<XrSwapchain, AppSwapchain> swapchains_;
  XrSpace viewSpace_ = XR_NULL_HANDLE;
  std::optional<XrQuaternionf> lastOrientation_;
  int64_t lastDisplayTime_ = 0;
  XrSpace lastSpace_ = XR_NULL_HANDLE;
  float smoothedSpeed_ = 0.0f;
  std::unique_ptr<imu::ImuPoseSource> imu_;  // pose_source = imu: head speed from the IMU
  SessionStats stats_;
  HistoryContinuity continuity_;  // under mutex_: frames without the app's world pass unlocked
  ImageDumper dumper_;
  bool mutableFormat_ = false;
  // jitter = on with a temporal method (the only ones that un-jitter the image): sub-pixel
  // Halton offsets injected into xrLocateViews' fov, undone in xrEndFrame.
  std::atomic<bool> jitter_ = false;  // read unlocked in xrLocateViews; a live method change sets it
  JitterTracker jitterTracker_;
  std::array<VkExtent2D, 2> viewSize_{};  // pixel size of each view's last filtered rect
  // Live settings: the first frame applies the current ones (UINT64_MAX is no generation).
  uint64_t liveGeneration_ = UINT64_MAX;
  std::atomic<bool> liveEnabled_ = true;  // `enabled` from the config file
  std::optional<Config> appliedConfig_;
  int64_t lastStatusNs_ = 0;
  bool statusDue_ = true;
  uint32_t debugFrames_ = 0;  // frames logged at debug level
};

}  // namespace steadyxr::layer
