// The session's start: frames pass through while the filter's pipelines compile, and once filtering
// has begun no frame waits again unless the user asks for new pipelines (a method switched live). The
// session summary and the status file count those late waits apart (frames_warming_up_late), so that
// a run under a real runtime (tests/layer/e2e) can ask for none; an app with a depth swapchain gets the depth
// variants made before its frames give depth. Pipelines are held back (and seen made) through
// InstanceState::holdBackPipelinesForTests, which makes each compile's order the test's choice.
#include "session_app.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <fstream>
#include <functional>
#include <string>
#include <thread>

namespace steadyxr::layer {
namespace {

using namespace session_rig;

constexpr int32_t kProbeBit = 128, kObservationBit = 8192;  // passSpecKey's, in specialisation[14]
constexpr size_t kDepthBits = 6;                            // passSpecKey's order

// The default's probe: the plain one (every frame) or the head-locked switch's (epoch frames).
bool isProbe(const core::PipelineDescription& d, bool observing) {
  return d.pass == "temporal" && d.specialisation.size() == 15 && (d.specialisation[14] & kProbeBit) != 0 &&
         ((d.specialisation[14] & kObservationBit) != 0) == observing;
}

// What the tests hold back and what they have seen compiled. The hook runs on the frame's thread (the
// filter asks it once a pipeline's compile has finished), but the flags are atomics all the same.
struct Holds {
  std::atomic<bool> plainProbe{false};
  std::atomic<bool> stereoPass{false};
  std::atomic<bool> switchProbeMade{false};
  std::atomic<bool> temporalPassMade{false};
  std::atomic<bool> depthVariantMade{false};  // a pipeline that reads depth (passSpecKey's depth bits)
  bool holdBack(const core::PipelineDescription& d) {
    if (isProbe(d, true)) switchProbeMade = true;
    if (d.pass == "temporal" && !isProbe(d, false) && !isProbe(d, true)) temporalPassMade = true;
    if (d.specialisation.size() == 15 && d.specialisation[kDepthBits] != 0) depthVariantMade = true;
    if (isProbe(d, false)) return plainProbe;
    if (d.pass == "stereo") return stereoPass;
    return false;
  }
};

App appWith(FakeRuntime& fake, Config cfg, Holds& holds) {
  return App(fake, std::move(cfg), true, VK_FORMAT_R8G8B8A8_UNORM, Layout::SideBySide,
             [&holds](const core::PipelineDescription& d) { return holds.holdBack(d); });
}

// Round 44's start-up bug (layer/core/src/filter_submit.cpp, recordProbes): with the switch's probe made
// before the plain one, a still head's frames were filtered and passed through in turn until the plain
// probe was made. Here the plain probe is held back until everything else is made: no frame may be
// filtered before it, and none may wait after.
TEST_F(SessionTest, FilteringOnceBegunGoesOnAndTheSummarySaysSo) {
  FakeRuntime fake(*gVk);
  Holds holds;
  holds.plainProbe = true;
  Config cfg;
  cfg.method = "steady";  // the default's temporal pass with its head-locked switch
  App app = appWith(fake, cfg, holds);
  const auto giveUp = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (!(holds.switchProbeMade && holds.temporalPassMade) && std::chrono::steady_clock::now() < giveUp) {
    EXPECT_EQ(app.frame(), XR_SUCCESS);
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_TRUE(holds.switchProbeMade && holds.temporalPassMade) << "the pipelines did not compile in 120 s";
  for (int i = 0; i < 8; ++i) EXPECT_EQ(app.frame(), XR_SUCCESS);
  EXPECT_EQ(app.session_->stats().framesFiltered, 0u) << "frames filtered before the plain probe was made";
  const uint64_t waited = app.passed(PassReason::Compiling);
  EXPECT_GE(waited, 8u);

  holds.plainProbe = false;
  for (int i = 0; i < 12; ++i) EXPECT_EQ(app.frame(), XR_SUCCESS);
  const SessionStats stats = app.session_->stats();
  EXPECT_EQ(stats.framesFiltered, 12u);
  EXPECT_EQ(stats.warmingUpLate, 0u);
  EXPECT_EQ(app.passed(PassReason::Compiling), waited);
  const std::string summary = stats.summary();
  EXPECT_NE(summary.find(" frames_warming_up=" + std::to_string(waited) + " frames_warming_up_late=0 "),
            std::string::npos)
      << summary;
}

// A method switched live after filtering began needs pipelines the session never used: its frames wait
// for them, and the summary counts them as late.
TEST_F(SessionTest, AMethodSwitchedLiveWaitsAndIsCountedLate) {
  FakeRuntime fake(*gVk);
  Holds holds;
  Config cfg;
  cfg.method = "taa";
  App app = appWith(fake, cfg, holds);
  ASSERT_TRUE(app.warmUp());
  for (int i = 0; i < 3; ++i) EXPECT_EQ(app.frame(), XR_SUCCESS);
  EXPECT_EQ(app.session_->stats().framesFiltered, 4u);
  EXPECT_EQ(app.session_->stats().warmingUpLate, 0u);
  const uint64_t waitedAtStart = app.passed(PassReason::Compiling);

  // The config file the layer watches, edited as a user would (tests/layer/live_test.cpp).
  const fs::path conf = app.dir_ / "steadyxr.conf";
  std::ofstream(conf) << "method = taa\n";
  const EnvLookup env = [conf](const std::string& name) -> std::optional<std::string> {
    if (name == "STEADYXR_CONFIG") return conf.string();
    return std::nullopt;
  };
  app.instance_->live =
      std::make_unique<LiveConfig>(loadConfig("app", env, nullptr), "app", env, *app.instance_->log);
  holds.stereoPass = true;
  std::ofstream(conf.string() + ".new") << "method = stereo\n";
  fs::rename(conf.string() + ".new", conf);
  const auto giveUp = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (app.instance_->live->generation() == 0 && std::chrono::steady_clock::now() < giveUp) {
    EXPECT_EQ(app.frame(), XR_SUCCESS);
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_EQ(app.instance_->live->generation(), 1u) << "the edit was not seen in 30 s";
  const uint64_t filteredAtSwitch = app.session_->stats().framesFiltered;
  for (int i = 0; i < 5; ++i) EXPECT_EQ(app.frame(), XR_SUCCESS);
  EXPECT_EQ(app.session_->stats().framesFiltered, filteredAtSwitch) << "filtered without the stereo pass";
  EXPECT_GE(app.session_->stats().warmingUpLate, 5u);
  holds.stereoPass = false;
  const auto stereoDeadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (app.session_->stats().framesFiltered == filteredAtSwitch &&
         std::chrono::steady_clock::now() < stereoDeadline) {
    EXPECT_EQ(app.frame(), XR_SUCCESS);
    std::this_thread::sleep_for(std::chrono::milliseconds(25));
  }
  EXPECT_GT(app.session_->stats().framesFiltered, filteredAtSwitch);
  const SessionStats stats = app.session_->stats();
  EXPECT_EQ(stats.warmingUpLate, app.passed(PassReason::Compiling) - waitedAtStart);
  EXPECT_NE(stats.summary().find(" frames_warming_up_late=" + std::to_string(stats.warmingUpLate) + " "),
            std::string::npos)
      << stats.summary();
}

// Round 45: an app with a depth swapchain may start giving depth half-way; the session tells the filter
// (core::Filter::setDepthMayChange), which then makes the depth variants of the frames' pipelines beforehand
// (tests/core/filter_test_pipelines.cpp, DepthThatStartsOrStopsHalfWayFindsItsPipelinesMade). An app without
// one never gets them: no compile for an input that cannot come. Neither app here gives depth.
TEST_F(SessionTest, ADepthSwapchainMakesTheDepthPipelinesBeforehand) {
  std::chrono::steady_clock::duration tookWithDepthSwapchain{};
  for (const bool depthSwapchain : {true, false}) {
    FakeRuntime fake(*gVk);
    Holds holds;
    Config cfg;
    cfg.method = "steady";
    App app = appWith(fake, cfg, holds);
    XrSwapchain depth = XR_NULL_HANDLE;
    if (depthSwapchain) {
      const auto ci =
          swapchainInfo(XR_SWAPCHAIN_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT, VK_FORMAT_D32_SFLOAT, 64, 32);
      ASSERT_EQ(app.session_->createSwapchain(&ci, &depth), XR_SUCCESS);
    }
    ASSERT_TRUE(app.warmUp());
    const auto start = std::chrono::steady_clock::now();
    // Without the depth swapchain, twice as long as it took with one (and a second at least).
    const auto until = depthSwapchain ? start + std::chrono::seconds(60)
                                      : start + std::max<std::chrono::steady_clock::duration>(
                                                    2 * tookWithDepthSwapchain, std::chrono::seconds(1));
    while (!holds.depthVariantMade && std::chrono::steady_clock::now() < until) {
      EXPECT_EQ(app.frame(), XR_SUCCESS);
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    if (depthSwapchain) tookWithDepthSwapchain = std::chrono::steady_clock::now() - start;
    EXPECT_EQ(holds.depthVariantMade, depthSwapchain) << "depth swapchain " << depthSwapchain;
    EXPECT_EQ(app.session_->stats().warmingUpLate, 0u);
    if (depth != XR_NULL_HANDLE) {
      EXPECT_EQ(app.session_->destroySwapchain(depth), XR_SUCCESS);
    }
  }
}

}  // namespace
}  // namespace steadyxr::layer
