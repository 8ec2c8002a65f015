// The layer's output swapchains (one per app colour swapchain, acquired and waited for each
// filtered frame) and the app images the layer has to ask the runtime for. Steps of
// Session::endFrame (session_frame.cpp) call these; locking: see Session in session.h.
#include "session.h"

#include <set>

namespace steadyxr::layer {
namespace {

constexpr XrDuration kOutputWaitNs = 1'000'000'000;  // bounded: never hang the frame loop

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

}  // namespace steadyxr::layer
