// A next layer for driving a Session in unit tests: it fakes the runtime's swapchain, space and
// frame calls over real Vulkan images (lavapipe), so tests can inject what Monado never does on
// demand: wait timeouts, XR_SESSION_LOSS_PENDING, rejected frames, refused swapchains, calls
// that block while another thread uses the layer. The real runtime is exercised by the e2e
// tests (tests/layer/e2e, tests/layer/probe).
#pragma once

#include "../core/gpu_image.h"
#include "session.h"

#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <vector>

namespace steadyxr::test {

class FakeRuntime {
 public:
  explicit FakeRuntime(core::VulkanContext& vk);
  ~FakeRuntime();
  layer::Dispatch dispatch() const;

  struct Chain {
    XrSwapchainCreateInfo info{};
    std::vector<std::unique_ptr<GpuImage>> images;
    std::deque<uint32_t> acquired;
    uint32_t nextIndex = 0;
    uint32_t acquireCalls = 0;
    bool waited = false;
  };

  // What the fake answers (set by the test; the fake's own state is under mutex).
  std::mutex mutex;
  std::map<XrSwapchain, Chain> chains;
  std::deque<XrResult> outputWaitResults;  // next results of waits on swapchains the app did not create
  XrResult endFrameResult = XR_SUCCESS;
  bool throwInCreateReferenceSpace = false;
  // Refuses swapchains the device cannot create as asked (as a runtime that validates against
  // its device does), with this result; and, if set, any that carry these usage bits.
  XrResult refusedResult = XR_ERROR_FEATURE_UNSUPPORTED;
  XrSwapchainUsageFlags refusedUsage = 0;
  std::function<void()> duringOutputWait;  // runs inside xrWaitSwapchainImage on a layer swapchain
  std::function<void()> duringEndFrame;    // runs inside xrEndFrame
  std::vector<XrSwapchain> appSwapchains;  // created through the session by the test's "app"
  std::vector<XrView> locatedViews;        // what xrLocateViews answers

  // Recorded.
  uint32_t createSwapchainCalls = 0;
  uint32_t endFrameCalls = 0;
  const XrFrameEndInfo* lastEndFrameInfo = nullptr;     // the pointer the runtime received
  XrSwapchain lastSubmittedSwapchain = XR_NULL_HANDLE;  // view 0 of the first projection layer
  std::vector<XrFovf> lastSubmittedFovs;                // each view's fov of that layer

  core::VulkanContext& vk;

 private:
  uintptr_t nextHandle_ = 0x1000;
  friend struct FakeCalls;
};

}  // namespace steadyxr::test
