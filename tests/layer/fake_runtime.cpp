#include "fake_runtime.h"

#include <algorithm>
#include <cstdio>
#include <stdexcept>

namespace steadyxr::test {
namespace {
FakeRuntime* gFake = nullptr;  // the one fake of the running test (C function pointers carry no state)
}

struct FakeCalls {
  // The fake's chain `s`, or null: the caller answers XR_ERROR_HANDLE_INVALID. Called with the
  // fake's mutex held.
  static FakeRuntime::Chain* chain(XrSwapchain s) {
    auto it = gFake->chains.find(s);
    return it == gFake->chains.end() ? nullptr : &it->second;
  }
  static XRAPI_ATTR XrResult XRAPI_CALL createSwapchain(XrSession, const XrSwapchainCreateInfo* info,
                                                        XrSwapchain* out) {
    FakeRuntime& f = *gFake;
    std::lock_guard lock(f.mutex);
    ++f.createSwapchainCalls;
    if (info == nullptr || out == nullptr) return XR_ERROR_VALIDATION_FAILURE;
    VkImageFormatProperties props{};
    const VkImageCreateFlags flags =
        (info->usageFlags & XR_SWAPCHAIN_USAGE_MUTABLE_FORMAT_BIT) ? VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT : 0;
    if (vkGetPhysicalDeviceImageFormatProperties(
            f.vk.physicalDevice(), static_cast<VkFormat>(info->format), VK_IMAGE_TYPE_2D,
            VK_IMAGE_TILING_OPTIMAL, layer::vulkanUsage(info->usageFlags), flags, &props) != VK_SUCCESS ||
        (info->usageFlags & f.refusedUsage) != 0)
      return f.refusedResult;
    FakeRuntime::Chain chain;
    chain.info = *info;
    const bool depth = layer::isDepthFormat(info->format);
    for (int i = 0; i < 3; ++i) {
      auto img =
          std::make_unique<GpuImage>(f.vk, static_cast<VkFormat>(info->format), info->width, info->height,
                                     info->arraySize, layer::vulkanUsage(info->usageFlags),
                                     (info->usageFlags & XR_SWAPCHAIN_USAGE_MUTABLE_FORMAT_BIT) != 0);
      // The layout the Vulkan binding promises between acquire-wait and release.
      img->transition(VK_IMAGE_LAYOUT_UNDEFINED, depth ? VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL
                                                       : VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
      chain.images.push_back(std::move(img));
    }
    *out = reinterpret_cast<XrSwapchain>(f.nextHandle_++);
    f.chains.emplace(*out, std::move(chain));
    return XR_SUCCESS;
  }
  static XRAPI_ATTR XrResult XRAPI_CALL destroySwapchain(XrSwapchain s) {
    std::lock_guard lock(gFake->mutex);
    return gFake->chains.erase(s) ? XR_SUCCESS : XR_ERROR_HANDLE_INVALID;
  }
  static XRAPI_ATTR XrResult XRAPI_CALL enumerateImages(XrSwapchain s, uint32_t capacity, uint32_t* count,
                                                        XrSwapchainImageBaseHeader* images) {
    std::lock_guard lock(gFake->mutex);
    FakeRuntime::Chain* c = chain(s);
    if (c == nullptr) return XR_ERROR_HANDLE_INVALID;
    const uint32_t n = static_cast<uint32_t>(c->images.size());
    *count = n;
    if (capacity == 0) return XR_SUCCESS;
    if (capacity < n) return XR_ERROR_SIZE_INSUFFICIENT;
    auto* vkImages = reinterpret_cast<XrSwapchainImageVulkanKHR*>(images);
    for (uint32_t i = 0; i < n; ++i) vkImages[i].image = c->images[i]->image();
    return XR_SUCCESS;
  }
  static XRAPI_ATTR XrResult XRAPI_CALL acquire(XrSwapchain s, const XrSwapchainImageAcquireInfo*,
                                                uint32_t* index) {
    std::lock_guard lock(gFake->mutex);
    FakeRuntime::Chain* found = chain(s);
    if (found == nullptr) return XR_ERROR_HANDLE_INVALID;
    FakeRuntime::Chain& c = *found;
    if (c.acquired.size() >= c.images.size()) return XR_ERROR_CALL_ORDER_INVALID;
    *index = c.nextIndex;
    c.acquired.push_back(c.nextIndex);
    c.nextIndex = (c.nextIndex + 1) % static_cast<uint32_t>(c.images.size());
    ++c.acquireCalls;
    c.waited = false;
    return XR_SUCCESS;
  }
  static XRAPI_ATTR XrResult XRAPI_CALL wait(XrSwapchain s, const XrSwapchainImageWaitInfo*) {
    FakeRuntime& f = *gFake;
    std::function<void()> during;
    XrResult r = XR_SUCCESS;
    {
      std::lock_guard lock(f.mutex);
      FakeRuntime::Chain* c = chain(s);
      if (c == nullptr) return XR_ERROR_HANDLE_INVALID;
      if (c->acquired.empty()) return XR_ERROR_CALL_ORDER_INVALID;
      const bool output =
          std::find(f.appSwapchains.begin(), f.appSwapchains.end(), s) == f.appSwapchains.end();
      if (output) {
        during = f.duringOutputWait;
        if (!f.outputWaitResults.empty()) {
          r = f.outputWaitResults.front();
          f.outputWaitResults.pop_front();
        }
      }
      if (XR_SUCCEEDED(r) && r != XR_TIMEOUT_EXPIRED) c->waited = true;
    }
    if (during) during();  // unlocked: it may call into the session from another thread
    return r;
  }
  static XRAPI_ATTR XrResult XRAPI_CALL release(XrSwapchain s, const XrSwapchainImageReleaseInfo*) {
    std::lock_guard lock(gFake->mutex);
    FakeRuntime::Chain* c = chain(s);
    if (c == nullptr) return XR_ERROR_HANDLE_INVALID;
    // As the spec: only a waited image can be released.
    if (c->acquired.empty() || !c->waited) return XR_ERROR_CALL_ORDER_INVALID;
    c->acquired.pop_front();
    c->waited = false;
    return XR_SUCCESS;
  }
  static XRAPI_ATTR XrResult XRAPI_CALL locateViews(XrSession, const XrViewLocateInfo*, XrViewState*,
                                                    uint32_t capacity, uint32_t* count, XrView* views) {
    std::lock_guard lock(gFake->mutex);
    const std::vector<XrView>& located = gFake->locatedViews;
    if (count) *count = static_cast<uint32_t>(located.size());
    if (capacity == 0 || views == nullptr) return XR_SUCCESS;
    if (capacity < located.size()) return XR_ERROR_SIZE_INSUFFICIENT;
    std::copy(located.begin(), located.end(), views);
    return XR_SUCCESS;
  }
  static XRAPI_ATTR XrResult XRAPI_CALL endFrame(XrSession, const XrFrameEndInfo* info) {
    FakeRuntime& f = *gFake;
    std::function<void()> during;
    XrResult r;
    {
      std::lock_guard lock(f.mutex);
      ++f.endFrameCalls;
      f.lastEndFrameInfo = info;
      f.lastSubmittedSwapchain = XR_NULL_HANDLE;
      f.lastSubmittedFovs.clear();
      if (info != nullptr && info->layers != nullptr && info->layerCount > 0 && info->layers[0] != nullptr &&
          info->layers[0]->type == XR_TYPE_COMPOSITION_LAYER_PROJECTION) {
        const auto* p = reinterpret_cast<const XrCompositionLayerProjection*>(info->layers[0]);
        if (p->views != nullptr && p->viewCount > 0)
          f.lastSubmittedSwapchain = p->views[0].subImage.swapchain;
        for (uint32_t v = 0; p->views != nullptr && v < p->viewCount; ++v)
          f.lastSubmittedFovs.push_back(p->views[v].fov);
      }
      during = f.duringEndFrame;
      r = info == nullptr || (info->layerCount > 0 && info->layers == nullptr) ? XR_ERROR_VALIDATION_FAILURE
                                                                               : f.endFrameResult;
    }
    if (during) during();
    return r;
  }
  static XRAPI_ATTR XrResult XRAPI_CALL createReferenceSpace(XrSession, const XrReferenceSpaceCreateInfo*,
                                                             XrSpace* space) {
    if (gFake->throwInCreateReferenceSpace) throw std::runtime_error("injected set-up failure");
    *space = reinterpret_cast<XrSpace>(uintptr_t{0x77});
    return XR_SUCCESS;
  }
  static XRAPI_ATTR XrResult XRAPI_CALL destroySpace(XrSpace) { return XR_SUCCESS; }
  static XRAPI_ATTR XrResult XRAPI_CALL locateSpace(XrSpace, XrSpace, XrTime, XrSpaceLocation* loc) {
    if (loc) loc->locationFlags = 0;
    return XR_SUCCESS;
  }
  static XRAPI_ATTR XrResult XRAPI_CALL resultToString(XrInstance, XrResult r,
                                                       char buffer[XR_MAX_RESULT_STRING_SIZE]) {
    std::snprintf(buffer, XR_MAX_RESULT_STRING_SIZE, "XrResult(%d)", static_cast<int>(r));
    return XR_SUCCESS;
  }
  static XRAPI_ATTR XrResult XRAPI_CALL systemProperties(XrInstance, XrSystemId, XrSystemProperties* p) {
    p->graphicsProperties.maxLayerCount = 16;
    return XR_SUCCESS;
  }
};

FakeRuntime::FakeRuntime(core::VulkanContext& ctx) : vk(ctx) {
  gFake = this;
}
FakeRuntime::~FakeRuntime() {
  gFake = nullptr;
}

layer::Dispatch FakeRuntime::dispatch() const {
  // Designated in Dispatch's member order; what the layer may do without is left null.
  return {.createSwapchain = FakeCalls::createSwapchain,
          .destroySwapchain = FakeCalls::destroySwapchain,
          .enumerateSwapchainImages = FakeCalls::enumerateImages,
          .acquireSwapchainImage = FakeCalls::acquire,
          .waitSwapchainImage = FakeCalls::wait,
          .releaseSwapchainImage = FakeCalls::release,
          .locateViews = FakeCalls::locateViews,
          .endFrame = FakeCalls::endFrame,
          .createReferenceSpace = FakeCalls::createReferenceSpace,
          .destroySpace = FakeCalls::destroySpace,
          .locateSpace = FakeCalls::locateSpace,
          .resultToString = FakeCalls::resultToString,
          .getSystemProperties = FakeCalls::systemProperties};
}

}  // namespace steadyxr::test
