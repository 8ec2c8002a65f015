// A Session on real Vulkan (lavapipe) behind a fault-injecting next layer (fake_runtime.h): the
// smaller faults of issue 15, each on the path the layer really takes.
#include "session_app.h"

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <future>
#include <thread>

namespace steadyxr::layer {
namespace {

using namespace session_rig;

TEST_F(SessionTest, InvalidFramesAreForwardedUntouched) {
  FakeRuntime fake(*gVk);
  App app(fake);
  ASSERT_TRUE(app.warmUp());
  auto info = makeXr<XrFrameEndInfo>(XR_TYPE_FRAME_END_INFO);
  info.layerCount = 1;  // layers = NULL: the SIGSEGV of issue 15
  EXPECT_EQ(app.session_->endFrame(&info), XR_ERROR_VALIDATION_FAILURE);
  EXPECT_EQ(fake.lastEndFrameInfo, &info);  // the app's own struct, not a copy
  EXPECT_EQ(app.session_->endFrame(nullptr), XR_ERROR_VALIDATION_FAILURE);
  EXPECT_EQ(app.passed(PassReason::InvalidFrame), 2u);
  EXPECT_EQ(app.frame(), XR_SUCCESS);  // and filtering goes on
  EXPECT_EQ(app.session_->stats().framesFiltered, 2u);
}

TEST_F(SessionTest, SetUpThatThrowsLeavesAPassThroughSession) {
  FakeRuntime fake(*gVk);
  fake.throwInCreateReferenceSpace = true;
  std::unique_ptr<App> app;
  ASSERT_NO_THROW(app = std::make_unique<App>(fake));
  EXPECT_FALSE(app->session_->filtering());
  EXPECT_EQ(app->frame(), XR_SUCCESS);
  EXPECT_EQ(fake.lastEndFrameInfo, &app->info_);  // passed through as submitted
  EXPECT_EQ(countOf(app->log(), "session set-up failed (injected set-up failure)"), 1u);
}

TEST_F(SessionTest, WaitTimeoutAndLossPendingDoNotStopFiltering) {
  FakeRuntime fake(*gVk);
  App app(fake);
  ASSERT_TRUE(app.warmUp());
  XrSwapchain output = XR_NULL_HANDLE;
  for (auto& [h, c] : fake.chains)
    if (h != app.swapchain_) output = h;
  ASSERT_NE(output, XR_NULL_HANDLE);
  fake.outputWaitResults = {XR_TIMEOUT_EXPIRED, XR_ERROR_RUNTIME_FAILURE, XR_SESSION_LOSS_PENDING};
  const uint32_t acquiresBefore = fake.chains[output].acquireCalls;
  const uint64_t filteredBefore = app.session_->stats().framesFiltered;
  EXPECT_EQ(app.frame(), XR_SUCCESS);  // timeout: passes through
  EXPECT_EQ(fake.lastSubmittedSwapchain, app.swapchain_);
  EXPECT_EQ(app.frame(), XR_SUCCESS);  // an error: passes through
  EXPECT_EQ(fake.lastSubmittedSwapchain, app.swapchain_);
  EXPECT_EQ(app.frame(), XR_SUCCESS);  // XR_SESSION_LOSS_PENDING is a success: filtered
  EXPECT_EQ(fake.lastSubmittedSwapchain, output);
  // The image acquired before the timeout was waited for again, not acquired anew.
  EXPECT_EQ(fake.chains[output].acquireCalls, acquiresBefore + 1);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(app.frame(), XR_SUCCESS);
  EXPECT_EQ(fake.lastSubmittedSwapchain, output);
  EXPECT_EQ(app.session_->stats().framesFiltered, filteredBefore + 4);
  EXPECT_EQ(app.passed(PassReason::XrError), 2u);
  EXPECT_TRUE(app.session_->filtering());
}

TEST_F(SessionTest, FramesTheRuntimeRejectsAreNotCountedAsFiltered) {
  FakeRuntime fake(*gVk);
  App app(fake);
  ASSERT_TRUE(app.warmUp());
  const uint64_t before = app.session_->stats().framesFiltered;
  fake.endFrameResult = XR_ERROR_POSE_INVALID;
  EXPECT_EQ(app.frame(), XR_ERROR_POSE_INVALID);  // the runtime's answer reaches the app
  EXPECT_EQ(app.frame(), XR_ERROR_POSE_INVALID);
  fake.endFrameResult = XR_SUCCESS;
  EXPECT_EQ(app.frame(), XR_SUCCESS);
  EXPECT_EQ(app.session_->stats().framesFiltered, before + 1);
  EXPECT_EQ(app.passed(PassReason::RuntimeRejected), 2u);
}

TEST_F(SessionTest, NoLayerLockIsHeldAcrossRuntimeCallsInEndFrame) {
  FakeRuntime fake(*gVk);
  App app(fake);
  ASSERT_TRUE(app.warmUp());
  // While the runtime is inside a call made by xrEndFrame, another thread of the app renders
  // (acquire, release) and locates views. With a lock held across the call these block.
  int completed = 0, calls = 0;
  std::vector<std::thread> threads;
  auto otherThread = [&] {
    ++calls;
    auto done = std::make_shared<std::promise<void>>();
    std::future<void> ready = done->get_future();
    threads.emplace_back([&app, done] {
      uint32_t index = 0, count = 0;
      app.session_->acquire(app.swapchain_, nullptr, &index);
      auto wi = makeXr<XrSwapchainImageWaitInfo>(XR_TYPE_SWAPCHAIN_IMAGE_WAIT_INFO);
      app.session_->next().waitSwapchainImage(app.swapchain_, &wi);
      app.session_->release(app.swapchain_, nullptr);
      app.session_->locateViews(nullptr, nullptr, 0, &count, nullptr);
      done->set_value();
    });
    // Not joined here: with a lock held across this call the thread could only finish after it, so it
    // cannot be ready within any wait; the wait is long only so that a loaded machine does not fail it.
    if (ready.wait_for(std::chrono::seconds(30)) == std::future_status::ready) ++completed;
  };
  fake.duringOutputWait = otherThread;
  fake.duringEndFrame = otherThread;
  EXPECT_EQ(app.frame(), XR_SUCCESS);
  for (std::thread& t : threads) t.join();
  fake.duringOutputWait = nullptr;
  fake.duringEndFrame = nullptr;
  EXPECT_EQ(calls, 2);
  EXPECT_EQ(completed, calls);
}

// jitter = 1 through the whole xrEndFrame path: the fov that xrLocateViews handed out jittered
// is recognised on submit, and the runtime gets the filtered image with the original fov; a fov
// the layer never handed out goes down as the app sent it.
TEST_F(SessionTest, JitteredFovIsUndoneOnSubmit) {
  FakeRuntime fake(*gVk);
  Config cfg;
  cfg.method = "taa";  // the temporal methods are the ones that undo the jitter
  cfg.jitter = true;
  App app(fake, cfg);
  ASSERT_TRUE(app.warmUp());  // the layer jitters once a filtered frame has told it the view sizes
  fake.locatedViews.assign(2, makeXr<XrView>(XR_TYPE_VIEW));
  for (XrView& v : fake.locatedViews) {
    v.pose.orientation.w = 1.0f;
    v.fov = App::kFov;
  }
  auto locateInfo = makeXr<XrViewLocateInfo>(XR_TYPE_VIEW_LOCATE_INFO);
  auto state = makeXr<XrViewState>(XR_TYPE_VIEW_STATE);
  std::array<XrView, 2> located{makeXr<XrView>(XR_TYPE_VIEW), makeXr<XrView>(XR_TYPE_VIEW)};
  uint32_t count = 0;
  ASSERT_EQ(app.session_->locateViews(&locateInfo, &state, 2, &count, located.data()), XR_SUCCESS);
  ASSERT_EQ(count, 2u);
  EXPECT_FALSE(sameFov(located[0].fov, App::kFov));

  const SessionStats before = app.session_->stats();
  app.fov_ = {located[0].fov, located[1].fov};  // rendered and submitted with the fov it was given
  EXPECT_EQ(app.frame(), XR_SUCCESS);
  const SessionStats jittered = app.session_->stats();
  EXPECT_EQ(jittered.framesFiltered, before.framesFiltered + 1);
  EXPECT_EQ(jittered.jitterUndone, before.jitterUndone + 2);
  EXPECT_NE(fake.lastSubmittedSwapchain, app.swapchain_);
  ASSERT_EQ(fake.lastSubmittedFovs.size(), 2u);
  for (const XrFovf& f : fake.lastSubmittedFovs) EXPECT_TRUE(sameFov(f, App::kFov));

  const XrFovf own{-0.6f, 0.6f, 0.6f, -0.6f};
  app.fov_ = {own, own};
  EXPECT_EQ(app.frame(), XR_SUCCESS);
  const SessionStats unjittered = app.session_->stats();
  EXPECT_EQ(unjittered.framesFiltered, jittered.framesFiltered + 1);
  EXPECT_EQ(unjittered.jitterUndone, jittered.jitterUndone);
  EXPECT_EQ(unjittered.jitterUnmatched, jittered.jitterUnmatched + 2);
  ASSERT_EQ(fake.lastSubmittedFovs.size(), 2u);
  for (const XrFovf& f : fake.lastSubmittedFovs) EXPECT_TRUE(sameFov(f, own));
}

// The largest difference between two images in any channel.
float largestDifference(const test::HostImage& a, const test::HostImage& b) {
  float worst = 0.0f;
  for (size_t i = 0; i < a.px.size() && i < b.px.size(); ++i)
    for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(a.px[i][c] - b.px[i][c]));
  return a.px.size() == b.px.size() ? worst : 1e9f;
}

// The history is the app's world as the layer last filtered it. After a frame without that world
// (a loading screen) or a gap longer than four app periods, the next frame starts afresh and shows
// the app's own image; across a shorter gap (three frames missed) plain taa blends its history in.
// The pictures: the "old level" a flat grey, the "new level" a checker of black and white pixels,
// whose 3x3 boxes hold the grey, so nothing but dropping the history keeps the grey out.
TEST_F(SessionTest, HistoryIsDroppedAfterAFrameWithoutTheAppsWorldOrALongGap) {
  FakeRuntime fake(*gVk);
  Config cfg;
  cfg.method = "taa";  // plain taa: the grey survives its clip, as the test needs
  App app(fake, cfg);
  const test::HostImage grey(64, 32, glm::vec4(0.5f, 0.5f, 0.5f, 1.0f));
  test::HostImage checker(64, 32);
  for (uint32_t y = 0; y < 32; ++y)
    for (uint32_t x = 0; x < 64; ++x) checker.at(x, y) = glm::vec4(glm::vec3(float((x + y) % 2)), 1.0f);
  app.content = grey;
  ASSERT_TRUE(app.warmUp());
  const auto newLevelAfter = [&](const std::function<void()>& between) {
    app.content = grey;
    for (int i = 0; i < 4; ++i) EXPECT_EQ(app.frame(), XR_SUCCESS);
    between();
    app.content = checker;
    EXPECT_EQ(app.frame(), XR_SUCCESS);
    EXPECT_NE(fake.lastSubmittedSwapchain, app.swapchain_);  // filtered
    return largestDifference(app.shown(), checker);
  };
  const uint64_t droppedBefore = app.session_->stats().historyDropped;
  EXPECT_GT(newLevelAfter([] {}), 0.2f);  // the grey blended in: the test can see a history
  EXPECT_GT(newLevelAfter([&] { app.time_ += 3 * 11'000'000; }), 0.2f);  // three frames missed: kept
  EXPECT_EQ(app.session_->stats().historyDropped, droppedBefore);
  XrResult empty = XR_ERROR_RUNTIME_FAILURE;
  EXPECT_LE(newLevelAfter([&] { empty = app.emptyFrame(); }), 1.0f / 255.0f);
  EXPECT_EQ(empty, XR_SUCCESS);
  EXPECT_LE(newLevelAfter([&] { app.time_ += 2'000'000'000; }), 1.0f / 255.0f);  // paused for 2 s
  EXPECT_EQ(app.session_->stats().historyDropped, droppedBefore + 2);
}

TEST_F(SessionTest, SwapchainsTheAppNeverEnumeratedAreFiltered) {
  FakeRuntime fake(*gVk);
  App app(fake, {}, /*enumerate=*/false);
  ASSERT_TRUE(app.warmUp());
  EXPECT_EQ(app.passed(PassReason::UnknownSwapchain), 0u);
  EXPECT_NE(fake.lastSubmittedSwapchain, app.swapchain_);
}

TEST_F(SessionTest, UncreatableDumpFolderDisablesDumpingOnce) {
  FakeRuntime fake(*gVk);
  const fs::path file = fs::temp_directory_path() / ("steadyxr-not-a-folder-" + std::to_string(::getpid()));
  std::ofstream(file) << "x";
  Config cfg;
  cfg.dumpFrames = 3;
  cfg.dumpDir = (file / "dump").string();  // below a regular file: cannot be created
  App app(fake, cfg);
  ASSERT_TRUE(app.warmUp());
  for (int i = 0; i < 4; ++i) EXPECT_EQ(app.frame(), XR_SUCCESS);
  EXPECT_EQ(countOf(app.log(), "dump: cannot create folder"), 1u);
  EXPECT_EQ(countOf(app.log(), "dump: cannot write"), 0u);          // nothing was read back or encoded
  EXPECT_EQ(fake.lastSubmittedSwapchain == app.swapchain_, false);  // filtering goes on
  fs::remove(file);
}

TEST_F(SessionTest, SessionsDoNotOverwriteEachOthersDumps) {
  const fs::path dir = fs::temp_directory_path() / ("steadyxr-dump-test-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  Config cfg;
  cfg.dumpFrames = 2;
  cfg.dumpDir = dir.string();
  for (int s = 0; s < 2; ++s) {
    FakeRuntime fake(*gVk);
    App app(fake, cfg);
    ASSERT_TRUE(app.warmUp());
    for (int i = 0; i < 2; ++i) app.frame();
  }
  size_t pngs = 0;
  for (const auto& e : fs::directory_iterator(dir)) pngs += e.path().extension() == ".png" ? 1 : 0;
  EXPECT_EQ(pngs, 2u * 2u * 2u * 2u);  // sessions x frames x eyes x {in, out}
  fs::remove_all(dir);
}

TEST_F(SessionTest, SwapchainRefusedForTheAppsOwnUsageIsRequestedOnce) {
  FakeRuntime fake(*gVk);
  App app(fake);
  auto ci = app.fake_.chains[app.swapchain_].info;
  ci.usageFlags = XR_SWAPCHAIN_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT;  // on a colour format: the app's own error
  const uint32_t before = fake.createSwapchainCalls;
  XrSwapchain s = XR_NULL_HANDLE;
  EXPECT_EQ(app.session_->createSwapchain(&ci, &s), XR_ERROR_FEATURE_UNSUPPORTED);
  EXPECT_EQ(fake.createSwapchainCalls, before + 1);
  EXPECT_EQ(countOf(app.log(), "refused SAMPLED"), 0u);
  // A runtime that refuses the added SAMPLED bit itself: retried once without it, said so.
  fake.refusedUsage = XR_SWAPCHAIN_USAGE_SAMPLED_BIT;
  ci.usageFlags = XR_SWAPCHAIN_USAGE_COLOR_ATTACHMENT_BIT;
  EXPECT_EQ(app.session_->createSwapchain(&ci, &s), XR_SUCCESS);
  EXPECT_EQ(fake.createSwapchainCalls, before + 3);
  EXPECT_EQ(countOf(app.log(), "refused SAMPLED"), 1u);
}

// XR_KHR_vulkan_enable (v1): the app's own instance version decides, read from its device.
TEST_F(SessionTest, V1DeviceVersionIsTheAppsOwn) {
  for (const uint32_t asked : {VK_API_VERSION_1_0, VK_API_VERSION_1_3}) {
    auto app = makeVk<VkApplicationInfo>(VK_STRUCTURE_TYPE_APPLICATION_INFO);
    app.apiVersion = asked;
    auto ici = makeVk<VkInstanceCreateInfo>(VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO);
    ici.pApplicationInfo = &app;
    VkInstance instance = VK_NULL_HANDLE;
    ASSERT_EQ(vkCreateInstance(&ici, nullptr, &instance), VK_SUCCESS);
    uint32_t n = 1;
    VkPhysicalDevice pd = VK_NULL_HANDLE;
    vkEnumeratePhysicalDevices(instance, &n, &pd);
    ASSERT_NE(pd, VK_NULL_HANDLE);
    VkPhysicalDeviceProperties props{};
    vkGetPhysicalDeviceProperties(pd, &props);
    const float priority = 1.0f;
    auto qci = makeVk<VkDeviceQueueCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO);
    qci.queueCount = 1;
    qci.pQueuePriorities = &priority;
    auto dci = makeVk<VkDeviceCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO);
    dci.queueCreateInfoCount = 1;
    dci.pQueueCreateInfos = &qci;
    VkDevice device = VK_NULL_HANDLE;
    ASSERT_EQ(vkCreateDevice(pd, &dci, nullptr, &device), VK_SUCCESS);
    const uint32_t got = deviceApiVersion(pd, device);
    if (asked == VK_API_VERSION_1_0) {
      EXPECT_EQ(got, VK_API_VERSION_1_0);
    } else {
      // Lavapipe reports 1.3 (Mesa 22.3) or 1.4 (Mesa 25): the probe tops out at 1.3.
      EXPECT_EQ(got,
                std::min(VK_API_VERSION_1_3, VK_MAKE_API_VERSION(0, VK_API_VERSION_MAJOR(props.apiVersion),
                                                                 VK_API_VERSION_MINOR(props.apiVersion), 0)));
    }
    vkDestroyDevice(device, nullptr);
    vkDestroyInstance(instance, nullptr);
  }
}

}  // namespace
}  // namespace steadyxr::layer
