// What the Session tests share: a Session on real Vulkan (lavapipe) behind a fault-injecting next layer
// (fake_runtime.h), driven by an "app" that submits frames as a real one does.
#pragma once

#include "fake_runtime.h"

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <sstream>
#include <string>
#include <thread>

#include <unistd.h>

namespace steadyxr::layer::session_rig {

using test::FakeRuntime;
namespace fs = std::filesystem;

// The suite's Vulkan device (SessionTest sets it up once for the binary).
inline core::VulkanContext* gVk = nullptr;

inline std::string readFile(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

inline bool sameFov(const XrFovf& a, const XrFovf& b) {
  return a.angleLeft == b.angleLeft && a.angleRight == b.angleRight && a.angleUp == b.angleUp &&
         a.angleDown == b.angleDown;
}

inline size_t countOf(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// A plain swapchain's create info: one sample, face, layer and mip level.
inline XrSwapchainCreateInfo swapchainInfo(XrSwapchainUsageFlags usage, VkFormat format, uint32_t width,
                                           uint32_t height) {
  auto ci = makeXr<XrSwapchainCreateInfo>(XR_TYPE_SWAPCHAIN_CREATE_INFO);
  ci.usageFlags = usage;
  ci.format = format;
  ci.sampleCount = 1;
  ci.width = width;
  ci.height = height;
  ci.faceCount = 1;
  ci.arraySize = 1;
  ci.mipCount = 1;
  return ci;
}

// How the app's one colour image holds its two views: side by side (64 x 32 px) or one above the other
// (32 x 64 px).
enum class Layout { SideBySide, Stacked };

// An "app": one session, one colour swapchain holding both views, frames submitted as a real app does.
class App {
 public:
  explicit App(FakeRuntime& fake, Config cfg = {}, bool enumerate = true,
               VkFormat format = VK_FORMAT_R8G8B8A8_UNORM, Layout layout = Layout::SideBySide,
               std::function<bool(const core::PipelineDescription&)> holdBack = {})
      : fake_(fake),
        layout_(layout),
        dir_(fs::temp_directory_path() / ("steadyxr-session-test-" + std::to_string(::getpid()))) {
    fs::create_directories(dir_);
    cfg.logFile = (dir_ / "layer.log").string();
    if (cfg.method == "default") cfg.method = "none";  // one small pipeline: compiles fast
    instance_ = std::make_shared<InstanceState>();
    instance_->handle = reinterpret_cast<XrInstance>(uintptr_t{0x11});
    instance_->next = fake.dispatch();
    instance_->config = cfg;
    instance_->log = std::make_unique<Logger>(LogLevel::Info, cfg.logFile);
    instance_->vulkanApiVersion = VK_API_VERSION_1_1;
    instance_->holdBackPipelinesForTests = std::move(holdBack);
    auto binding = makeXr<XrGraphicsBindingVulkanKHR>(XR_TYPE_GRAPHICS_BINDING_VULKAN_KHR);
    binding.instance = gVk->instance();
    binding.physicalDevice = gVk->physicalDevice();
    binding.device = gVk->device();
    binding.queueFamilyIndex = gVk->queueFamilyIndex();
    session_ = std::make_unique<Session>(instance_, reinterpret_cast<XrSession>(uintptr_t{0x22}), 1, binding);
    auto ci = swapchainInfo(XR_SWAPCHAIN_USAGE_COLOR_ATTACHMENT_BIT, format,
                            layout == Layout::Stacked ? 32 : 64, layout == Layout::Stacked ? 64 : 32);
    EXPECT_EQ(session_->createSwapchain(&ci, &swapchain_), XR_SUCCESS);
    {
      std::lock_guard lock(fake.mutex);
      fake.appSwapchains.push_back(swapchain_);
    }
    if (enumerate) {
      uint32_t n = 0;
      session_->enumerateImages(swapchain_, 0, &n, nullptr);
      std::vector<XrSwapchainImageVulkanKHR> imgs(
          n, makeXr<XrSwapchainImageVulkanKHR>(XR_TYPE_SWAPCHAIN_IMAGE_VULKAN_KHR));
      session_->enumerateImages(swapchain_, n, &n,
                                reinterpret_cast<XrSwapchainImageBaseHeader*>(imgs.data()));
    }
  }
  ~App() {
    session_.reset();
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

  // Renders (acquire, wait, release) and submits one frame; returns xrEndFrame's result.
  XrResult frame() {
    uint32_t index = 0;
    EXPECT_EQ(session_->acquire(swapchain_, nullptr, &index), XR_SUCCESS);
    auto wi = makeXr<XrSwapchainImageWaitInfo>(XR_TYPE_SWAPCHAIN_IMAGE_WAIT_INFO);
    EXPECT_EQ(session_->next().waitSwapchainImage(swapchain_, &wi), XR_SUCCESS);
    if (content) fake_.chains[swapchain_].images[index]->upload(*content, 0, kRenderedLayout);
    EXPECT_EQ(session_->release(swapchain_, nullptr), XR_SUCCESS);
    for (uint32_t v = 0; v < 2; ++v) {
      views_[v] = makeXr<XrCompositionLayerProjectionView>(XR_TYPE_COMPOSITION_LAYER_PROJECTION_VIEW);
      views_[v].pose.orientation.w = 1.0f;
      views_[v].fov = fov_[v];
      views_[v].subImage.swapchain = swapchain_;
      views_[v].subImage.imageRect = {rectOffset(v), {renderSize, renderSize}};
    }
    proj_ = makeXr<XrCompositionLayerProjection>(XR_TYPE_COMPOSITION_LAYER_PROJECTION);
    proj_.viewCount = 2;
    proj_.views = views_.data();
    layers_[0] = reinterpret_cast<const XrCompositionLayerBaseHeader*>(&proj_);
    info_ = makeXr<XrFrameEndInfo>(XR_TYPE_FRAME_END_INFO);
    info_.displayTime = time_ += 11'000'000;
    info_.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
    info_.layerCount = 1;
    info_.layers = layers_.data();
    return session_->endFrame(&info_);
  }
  // A frame without the app's world (a loading screen, a pause): no layer at all.
  XrResult emptyFrame() {
    info_ = makeXr<XrFrameEndInfo>(XR_TYPE_FRAME_END_INFO);
    info_.displayTime = time_ += 11'000'000;
    info_.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
    return session_->endFrame(&info_);
  }
  // View v's rect's offset: the top-left of its part of the image, moved by `shift`.
  XrOffset2Di rectOffset(uint32_t v) const {
    const int32_t part = 32 * int32_t(v);
    return layout_ == Layout::Stacked ? XrOffset2Di{shift.x, part + shift.y}
                                      : XrOffset2Di{part + shift.x, shift.y};
  }
  // What the runtime was last handed to show: the layer's output image, both views in their parts.
  test::HostImage shown() {
    FakeRuntime::Chain& out = fake_.chains[fake_.lastSubmittedSwapchain];
    const auto n = static_cast<uint32_t>(out.images.size());
    return out.images[(out.nextIndex + n - 1) % n]->download(0, kRenderedLayout);  // released last
  }
  // Frames until the first is filtered (the pipelines compile in the background). The deadline is wall
  // time and generous: under a loaded ctest -j, with Mesa's shader cache cold, lavapipe's compiles of the
  // default's pipelines take seconds, and a test that gives up early fails for the machine's load.
  bool warmUp() {
    const auto giveUp = std::chrono::steady_clock::now() + std::chrono::seconds(120);
    do {
      frame();
      if (session_->stats().framesFiltered > 0) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(25));
    } while (std::chrono::steady_clock::now() < giveUp);
    return false;
  }
  uint64_t passed(PassReason r) { return session_->stats().passed[static_cast<size_t>(r)]; }
  std::string log() const { return readFile(dir_ / "layer.log"); }

  FakeRuntime& fake_;
  Layout layout_;
  fs::path dir_;
  std::shared_ptr<InstanceState> instance_;
  std::unique_ptr<Session> session_;
  XrSwapchain swapchain_ = XR_NULL_HANDLE;
  static constexpr XrFovf kFov{-0.7f, 0.7f, 0.7f, -0.7f};
  std::array<XrFovf, 2> fov_{kFov, kFov};  // what the app submits for each view
  std::array<XrCompositionLayerProjectionView, 2> views_{};
  XrCompositionLayerProjection proj_{};
  std::array<const XrCompositionLayerBaseHeader*, 1> layers_{};
  XrFrameEndInfo info_{};
  XrTime time_ = 1'000'000'000;
  std::optional<test::HostImage> content;  // what each frame renders, if set
  int32_t renderSize = 32;  // each view's rect: this square at the top-left of its part of the image,
  XrOffset2Di shift{0, 0};  // moved by this much
  // The Vulkan binding's layout between wait and release, and the runtime's after release.
  static constexpr VkImageLayout kRenderedLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
};

class SessionTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    std::string err;
    ctx_ = core::VulkanContext::createOwned({}, &err);
    ASSERT_TRUE(ctx_) << err;
    gVk = ctx_.get();
  }
  static void TearDownTestSuite() {
    gVk = nullptr;
    ctx_.reset();
  }
  void SetUp() override { ASSERT_TRUE(ctx_); }
  static inline std::unique_ptr<core::VulkanContext> ctx_;
};

}  // namespace steadyxr::layer::session_rig
