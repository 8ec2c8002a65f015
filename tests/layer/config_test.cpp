#include "config.h"

#include <gtest/gtest.h>

#include <map>

namespace steadyxr::layer {
namespace {

EnvLookup envOf(std::map<std::string, std::string> vars) {
  return [vars = std::move(vars)](const std::string& name) -> std::optional<std::string> {
    auto it = vars.find(name);
    if (it == vars.end()) return std::nullopt;
    return it->second;
  };
}

bool mentions(const std::vector<std::string>& messages, const std::string& a, const std::string& b) {
  for (const auto& m : messages) {
    if (m.find(a) != std::string::npos && m.find(b) != std::string::npos) return true;
  }
  return false;
}

TEST(Config, DefaultsWithoutFileOrEnvironment) {
  std::vector<std::string> messages;
  const Config c = resolveConfig({}, "app", envOf({}), &messages);
  EXPECT_TRUE(c.enabled);
  EXPECT_EQ(c.method, "default");
  EXPECT_EQ(c.poseSource, PoseSourceKind::Runtime);
  EXPECT_EQ(c.logLevel, LogLevel::Info);
  EXPECT_EQ(c.dumpFrames, 0u);
  EXPECT_FALSE(c.jitter);
  EXPECT_TRUE(messages.empty());
}

TEST(Config, ParsesGlobalAndSections) {
  std::vector<std::string> messages;
  const ConfigText t = parseConfigText(
      "# comment\n method = taa \nw_min=0.25\n\n[hello_xr]\nmethod = none  # per app\n[other]\nenabled=0\n",
      &messages);
  EXPECT_TRUE(messages.empty());
  EXPECT_EQ(t.global.at("method"), "taa");
  EXPECT_EQ(t.sections.at("hello_xr").at("method"), "none");
  const Config forHello = resolveConfig(t, "hello_xr", envOf({}), &messages);
  EXPECT_EQ(forHello.method, "none");
  EXPECT_FLOAT_EQ(forHello.params.wMin, 0.25f);
  EXPECT_TRUE(forHello.enabled);
  const Config forOther = resolveConfig(t, "other", envOf({}), &messages);
  EXPECT_EQ(forOther.method, "taa");
  EXPECT_FALSE(forOther.enabled);
}

TEST(Config, EnvironmentOverridesFile) {
  std::vector<std::string> messages;
  const ConfigText t = parseConfigText("method = taa\n[app]\nlog_level = debug\n", &messages);
  const Config c = resolveConfig(
      t, "app", envOf({{"STEADYXR_METHOD", "hmtaa+stereo"}, {"STEADYXR_LOG_LEVEL", "error"}}), &messages);
  EXPECT_EQ(c.method, "hmtaa+stereo");
  EXPECT_EQ(c.logLevel, LogLevel::Error);
}

TEST(Config, BadValuesKeepDefaultsAndNameTheKey) {
  std::vector<std::string> messages;
  const ConfigText t =
      parseConfigText("method = sharpen\nw_min = 7\ndump_frames = -3\nh_max = nan\n", &messages);
  const Config c = resolveConfig(t, "app", envOf({{"STEADYXR_POSE_SOURCE", "gps"}}), &messages);
  EXPECT_EQ(c.method, "default");
  EXPECT_FLOAT_EQ(c.params.wMin, core::Params{}.wMin);
  EXPECT_EQ(c.dumpFrames, 0u);
  EXPECT_FLOAT_EQ(c.params.hMaxDegPerSec, core::Params{}.hMaxDegPerSec);
  EXPECT_EQ(c.poseSource, PoseSourceKind::Runtime);
  EXPECT_TRUE(mentions(messages, "'method'", "default"));
  EXPECT_TRUE(mentions(messages, "'w_min'", "0.3"));
  EXPECT_TRUE(mentions(messages, "'dump_frames'", "0"));
  EXPECT_TRUE(mentions(messages, "'h_max'", "25"));
  EXPECT_TRUE(mentions(messages, "'pose_source'", "STEADYXR_POSE_SOURCE"));
}

TEST(Config, MalformedLinesAndUnknownKeysAreReported) {
  std::vector<std::string> messages;
  const ConfigText t = parseConfigText("just words\n[broken\n= value\ncolour = red\n", &messages);
  EXPECT_EQ(messages.size(), 3u);
  resolveConfig(t, "app", envOf({}), &messages);
  EXPECT_TRUE(mentions(messages, "unknown key", "'colour'"));
}

TEST(Config, StartsDisabled) {
  std::vector<std::string> messages;
  EXPECT_FALSE(resolveConfig({}, "a", envOf({{"STEADYXR_ENABLED", "0"}}), &messages).enabled);
  EXPECT_FALSE(resolveConfig({}, "a", envOf({{"STEADYXR_DISABLE", "1"}}), &messages).enabled);
  EXPECT_TRUE(resolveConfig({}, "a", envOf({{"STEADYXR_DISABLE", "0"}}), &messages).enabled);
}

TEST(Config, ImuAndDumpKeys) {
  std::vector<std::string> messages;
  const Config c = resolveConfig(
      parseConfigText("pose_source = IMU\nimu_device = 1209:5a17\ndump_frames = 5\n"
                      "dump_dir = /tmp/d\njitter = on\nsample_count = 2\nhistory_filter = Catmull-Rom\n",
                      &messages),
      "a", envOf({}), &messages);
  EXPECT_TRUE(messages.empty());
  EXPECT_EQ(c.poseSource, PoseSourceKind::Imu);
  EXPECT_EQ(c.imuDevice, "1209:5a17");
  EXPECT_EQ(c.dumpFrames, 5u);
  EXPECT_EQ(c.dumpDir, "/tmp/d");
  EXPECT_TRUE(c.jitter);
  EXPECT_EQ(c.params.sampleCount, 2u);
  EXPECT_EQ(c.params.historyFilter, steadyxr::core::HistoryFilter::CatmullRom);
  messages.clear();
  const Config bad =
      resolveConfig(parseConfigText("history_filter = lanczos\n", &messages), "a", envOf({}), &messages);
  EXPECT_EQ(bad.params.historyFilter, steadyxr::core::HistoryFilter::Bilinear);
  EXPECT_TRUE(mentions(messages, "history_filter", "lanczos"));
}

TEST(Config, SteadyKeys) {
  std::vector<std::string> messages;
  const Config c = resolveConfig(
      parseConfigText("method = steady+stereo\nsteady_alpha_floor = 0.125\nsteady_blur_budget_px2 = 0.25\n"
                      "steady_footprint = 0\nsteady_nearest_depth_m = 2\nsteady_confidence = off\n"
                      "steady_clip_rejects = on\nsteady_interpolated = 1\n",
                      &messages),
      "a", envOf({}), &messages);
  EXPECT_TRUE(messages.empty()) << (messages.empty() ? "" : messages[0]);
  EXPECT_EQ(c.params.temporal, steadyxr::core::TemporalMethod::Steady);
  EXPECT_FLOAT_EQ(c.params.steadyAlphaFloor, 0.125f);
  EXPECT_FLOAT_EQ(c.params.steadyBlurBudgetPx2, 0.25f);
  EXPECT_FLOAT_EQ(c.params.steadyFootprint, 0.0f);
  EXPECT_FLOAT_EQ(c.params.steadyNearestDepthM, 2.0f);
  EXPECT_FALSE(c.params.steadyConfidence);
  EXPECT_TRUE(c.params.steadyClipRejects);
  EXPECT_TRUE(c.params.steadyInterpolated);
  messages.clear();
  const Config bad =
      resolveConfig(parseConfigText("steady_footprint = 0.5\nsteady_confidence = maybe\n", &messages), "a",
                    envOf({}), &messages);
  EXPECT_FLOAT_EQ(bad.params.steadyFootprint, steadyxr::core::Params{}.steadyFootprint);
  EXPECT_TRUE(bad.params.steadyConfidence);
  EXPECT_TRUE(mentions(messages, "steady_footprint", "0.5"));
  EXPECT_TRUE(mentions(messages, "steady_confidence", "maybe"));
}

TEST(Config, FileSearchOrder) {
  const auto none = [](const std::string&) { return false; };
  const auto all = [](const std::string&) { return true; };
  EXPECT_EQ(findConfigFile(envOf({{"STEADYXR_CONFIG", "/x.conf"}}), all).value(), "/x.conf");
  EXPECT_EQ(findConfigFile(envOf({}), all).value(), "steadyxr.conf");
  const auto xdgOnly = [](const std::string& p) { return p == "/xdg/steadyxr/steadyxr.conf"; };
  EXPECT_EQ(findConfigFile(envOf({{"XDG_CONFIG_HOME", "/xdg"}, {"HOME", "/h"}}), xdgOnly).value(),
            "/xdg/steadyxr/steadyxr.conf");
  const auto homeOnly = [](const std::string& p) { return p == "/h/.config/steadyxr/steadyxr.conf"; };
  EXPECT_EQ(findConfigFile(envOf({{"HOME", "/h"}}), homeOnly).value(), "/h/.config/steadyxr/steadyxr.conf");
  EXPECT_FALSE(findConfigFile(envOf({{"HOME", "/h"}}), none).has_value());
}

TEST(Config, MethodNames) {
  for (const char* ok :
       {"none", "fxaa", "taa", "hmtaa", "vtaa", "hybrid", "stereo", "taa+stereo", "default"}) {
    EXPECT_TRUE(isKnownMethodName(ok)) << ok;
  }
  for (const char* bad : {"", "+stereo", "stereo+stereo", "TAA", "msaa4"})
    EXPECT_FALSE(isKnownMethodName(bad)) << bad;
  EXPECT_EQ(envNameForKey("log_level"), "STEADYXR_LOG_LEVEL");
}

}  // namespace
}  // namespace steadyxr::layer
