// Pure helpers for xrEndFrame: which projection layers the layer can filter (and why not), and
// copies of the app's structs that point at the layer's own swapchains. No OpenXR calls here.
#pragma once

#include <time.h>
#include <vulkan/vulkan.h>
#ifndef XR_USE_TIMESPEC
#define XR_USE_TIMESPEC
#endif
#ifndef XR_USE_GRAPHICS_API_VULKAN
#define XR_USE_GRAPHICS_API_VULKAN
#endif
#include <openxr/openxr.h>
#include <openxr/openxr_platform.h>

#include "steadyxr/core/jitter.h"
#include "steadyxr/core/params.h"

#include <array>
#include <cstdint>
#include <deque>
#include <functional>
#include <optional>
#include <string_view>
#include <vector>

namespace steadyxr::layer {

// Zero-initialised OpenXR / Vulkan structs with their type tag set.
template <typename T>
T makeXr(XrStructureType type, const void* next = nullptr) {
  T v{};
  v.type = type;
  v.next = const_cast<decltype(v.next)>(next);
  return v;
}
template <typename T>
T makeVk(VkStructureType type) {
  T v{};
  v.sType = type;
  return v;
}

// Why a frame (or one projection layer) was passed through untouched.
enum class PassReason : uint8_t {
  Disabled,
  NotVulkan,
  NoProjectionLayer,
  ViewCount,
  UnknownSwapchain,
  NoReleasedImage,
  UnsupportedFormat,
  BadImageRect,
  MissingPose,
  OutputSwapchain,
  XrError,
  FilterError,
  Compiling,             // the filter's pipelines are still compiling in the background (not a failure)
  InvalidFrame,          // the XrFrameEndInfo failed scanFrame: forwarded untouched
  UnpremultipliedAlpha,  // alpha-blended with unpremultiplied colour (layer/xr/README.md)
  RuntimeRejected,       // filtered, but the runtime's xrEndFrame failed: not counted as filtered
  Count
};
std::string_view toString(PassReason r);

// What the layer knows about one of the app's swapchains.
struct SwapchainFacts {
  int64_t format = 0;
  uint32_t width = 0;
  uint32_t height = 0;
  uint32_t arraySize = 1;
  XrSwapchainUsageFlags usage = 0;
  bool hasReleasedImage = false;
  bool imagesKnown = false;
};
using SwapchainLookup = std::function<std::optional<SwapchainFacts>(XrSwapchain)>;

bool isFilterableColorFormat(int64_t vkFormat);
bool isSrgbFormat(int64_t vkFormat);
bool isDepthFormat(int64_t vkFormat);
bool isValidPose(const XrPosef& pose);
bool isValidFov(const XrFovf& fov);

// Bounds on what the layer reads of the app's structs: it is a guest in the app's process and
// must never fault on bad input, so every pointer and count is checked before it is read.
inline constexpr uint32_t kMaxNextChain = 64;  // `next` structs walked at most: a cycle ends the walk
// XR_MIN_COMPOSITION_LAYERS_SUPPORTED (OpenXR 1.0 spec, XrSystemGraphicsProperties): every
// runtime takes at least this many layers; used when the runtime's own limit is unknown.
inline constexpr uint32_t kMinLayerLimit = 16;
inline constexpr uint32_t kMaxLayerLimit = 4096;  // a runtime reporting more is not believed

// Why an XrFrameEndInfo is forwarded untouched (the runtime or the validation layer answers it).
enum class FrameProblem : uint8_t { None, NullInfo, WrongType, TooManyLayers, NullLayers, NullLayer };
std::string_view toString(FrameProblem p);

struct FrameScan {
  FrameProblem problem = FrameProblem::None;
  std::optional<uint32_t> projection;  // the first projection layer: the one the layer filters
  bool ok() const { return problem == FrameProblem::None; }
};
// Reads the frame only as far as it is valid: layerCount <= maxLayerCount (the runtime's
// XrSystemGraphicsProperties::maxLayerCount; larger counts are refused by the runtime with
// XR_ERROR_LAYER_LIMIT_EXCEEDED, so the array is never read past that), a non-null array, no
// null entry. A frame with a problem must be forwarded exactly as the app submitted it.
FrameScan scanFrame(const XrFrameEndInfo* info, uint32_t maxLayerCount);

// nullopt: the projection layer can be filtered.
std::optional<PassReason> checkProjection(const XrCompositionLayerProjection& layer,
                                          const SwapchainLookup& lookup);

// The chained XrCompositionLayerDepthInfoKHR of a projection view, if any.
const XrCompositionLayerDepthInfoKHR* findDepthInfo(const XrCompositionLayerProjectionView& view);

// Whether the filter could ever read a swapchain created like this (single-sample, not
// protected, not a cube map); others are left exactly as the app asked and pass through.
bool isReadableSwapchain(const XrSwapchainCreateInfo& info);
// The usage the layer asks for on the app's swapchains (so the filter can sample them).
XrSwapchainUsageFlags appSwapchainUsage(XrSwapchainUsageFlags requested);
// The layer's output swapchain for an app colour swapchain: same format, size and array size.
XrSwapchainCreateInfo outputSwapchainInfo(const XrSwapchainCreateInfo& app, bool mutableFormatSupported);
// Vulkan usage bits implied by OpenXR swapchain usage bits (what the runtime must at least set).
VkImageUsageFlags vulkanUsage(XrSwapchainUsageFlags usage);

using core::halton;  // Halton low-discrepancy sequence value (steadyxr/core/jitter.h)
// The fov whose image grid is shifted by (dxPx, dyPx) pixels of a width x height image
// (x right, y down): the sub-pixel jitter the layer can inject through xrLocateViews.
XrFovf jitterFov(const XrFovf& fov, float dxPx, float dyPx, uint32_t width, uint32_t height);

using core::undoesJitter;  // steadyxr/core/jitter.h

// The jitter of one submitted projection view as the filter core needs it.
struct ViewUnjitter {
  XrFovf fov{};          // the fov to filter on and submit (the unjittered one when matched)
  float jitterPx[2]{};   // core::ViewFrame::jitterPx: the image's grid offset, x right, y down
  bool matched = false;  // the submitted fov is one the layer jittered
};

// What the layer's jitter did on its last xrLocateViews calls, so that xrEndFrame can
// recognise a jittered fov the app submits and undo it. The caller serialises access.
class JitterTracker {
 public:
  static constexpr uint32_t kCalls = 8;  // calls remembered (apps submit the newest or the one before)
  static constexpr uint32_t kMaxViews = 2;
  static constexpr float kMatchRad = 1e-6f;  // per angle; apps copy the fov, so it matches exactly

  // Jitters the fovs of one xrLocateViews call in place with the next Halton(2,3) offset in
  // [-0.5, 0.5) pixels (period 8); sizes[i] is view i's image size. Views with an invalid fov
  // or a zero size are left alone. Returns how many views were jittered.
  uint32_t apply(XrFovf* fovs, const VkExtent2D* sizes, uint32_t count);
  // The submitted view `view` of `size` pixels: the newest recorded jitter whose jittered fov
  // matches `submitted` (jitterPx scaled to `size`), else `submitted` with no jitter.
  ViewUnjitter find(uint32_t view, const XrFovf& submitted, VkExtent2D size) const;
  uint32_t recordedCalls() const { return count_; }

 private:
  struct View {
    XrFovf original;
    XrFovf jittered;
    VkExtent2D size;
    bool valid;
  };
  struct Call {
    std::array<View, kMaxViews> views;
    float dxPx, dyPx;
  };
  std::array<Call, kCalls> ring_{};
  uint32_t next_ = 0;         // ring slot of the next call
  uint32_t count_ = 0;        // recorded calls, up to kCalls
  uint32_t jitterCalls_ = 0;  // calls jittered so far: core::haltonJitterPx's frame index
};

// Owns the copies handed to the next xrEndFrame. The app's structs are never modified; the
// copies keep the app's `next` chains (depth info still names the app's depth swapchain).
class FrameRewrite {
 public:
  // `app` must have passed scanFrame; anything else is kept as is (never read) and
  // replaceProjection does nothing.
  explicit FrameRewrite(const XrFrameEndInfo& app);
  // Replaces layer `index` (a projection layer) by a copy whose view i uses swapchains[i];
  // `fovs` (optional) replaces the views' fov (un-jitter).
  void replaceProjection(uint32_t index, const std::vector<XrSwapchain>& swapchains,
                         const std::vector<XrFovf>* fovs = nullptr);
  const XrFrameEndInfo& info() const { return info_; }
  uint32_t replacedCount() const { return replaced_; }

 private:
  XrFrameEndInfo info_;
  std::vector<const XrCompositionLayerBaseHeader*> layers_;
  std::deque<XrCompositionLayerProjection> projections_;  // deque: stable addresses
  std::deque<std::vector<XrCompositionLayerProjectionView>> views_;
  uint32_t replaced_ = 0;
};

}  // namespace steadyxr::layer
