#include "config.h"

#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>

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
  EXPECT_TRUE(mentions(messages, "method = sharpen", "default default"));
  EXPECT_TRUE(mentions(messages, "w_min = 7", "default 0.3"));
  EXPECT_TRUE(mentions(messages, "dump_frames = -3", "default 0"));
  EXPECT_TRUE(mentions(messages, "h_max = nan", "default 25"));
  EXPECT_TRUE(mentions(messages, "STEADYXR_POSE_SOURCE = gps", "environment"));
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
      parseConfigText(
          "method = steady+stereo\nsteady_alpha_floor = 0.125\nsteady_blur_budget_px2 = 0.25\n"
          "steady_footprint = 0\nsteady_nearest_depth_m = 2\nsteady_confidence = off\n"
          "steady_clip_rejects = on\nsteady_interpolated = 1\nsteady_clip_gamma = 0.75\n"
          "steady_footprint_encoded = off\nsteady_history_blur_per_axis = off\nsteady_output_hold = 0.5\n"
          "steady_blur_noise_trade = off\n"
          "steady_clip_holds_current = on\nsteady_clip_curvature = off\n"
          "steady_clip_curvature_centred = off\nsteady_clip_curvature_centred_gated = on\n"
          "steady_clip_quant_srgb = off\nsteady_noise_estimate = on\nsteady_noise_residual_over_time = off\n"
          "steady_noise_change_test = off\nsteady_gain_compensation = off\n"
          "steady_gain_relights_admitted = off\n"
          "steady_unexplained_frame_resets = off\n"
          "steady_resolved_edges = off\n"
          "steady_head_locked_switch = off\n"
          "stereo_inverse_variance = off\n"
          "stereo_tap_curvature = off\nstereo_clip_gamma_after_steady = 1.5\n",
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
  EXPECT_FLOAT_EQ(c.params.steadyClipGamma, 0.75f);
  EXPECT_FALSE(c.params.steadyFootprintEncoded);
  EXPECT_FALSE(c.params.steadyHistoryBlurPerAxis);
  EXPECT_FALSE(c.params.steadyBlurNoiseTrade);  // on by default: off here shows the key is read
  EXPECT_FLOAT_EQ(c.params.steadyOutputHold, 0.5f);
  EXPECT_TRUE(c.params.steadyClipHoldsCurrent);
  EXPECT_FALSE(c.params.steadyClipCurvature);             // on by default: off here shows the key is read
  EXPECT_FALSE(c.params.steadyClipCurvatureCentred);      // on by default: off here shows the key is read
  EXPECT_TRUE(c.params.steadyClipCurvatureCentredGated);  // off by default: on here shows the key is read
  EXPECT_FALSE(c.params.steadyClipQuantSrgb);             // on by default: off here shows the key is read
  EXPECT_TRUE(c.params.steadyNoiseEstimate);              // off by default: on here shows the key is read
  EXPECT_FALSE(c.params.steadyNoiseResidualOverTime);
  EXPECT_FALSE(c.params.steadyNoiseChangeTest);         // on by default: off here shows the key is read
  EXPECT_FALSE(c.params.steadyGainCompensation);        // on by default: off here shows the key is read
  EXPECT_FALSE(c.params.steadyGainRelightsAdmitted);    // on by default: off here shows the key is read
  EXPECT_FALSE(c.params.steadyUnexplainedFrameResets);  // on by default: off here shows the key is read
  EXPECT_FALSE(c.params.steadyResolvedEdges);           // on by default: off here shows the key is read
  EXPECT_FALSE(c.params.steadyHeadLockedSwitch);        // on by default: off here shows the key is read
  EXPECT_FALSE(c.params.stereoInverseVariance);
  EXPECT_FALSE(c.params.stereoTapCurvature);
  EXPECT_FLOAT_EQ(c.params.stereoClipGammaAfterSteady, 1.5f);
  messages.clear();
  const Config bad = resolveConfig(
      parseConfigText("steady_footprint = 0.5\nsteady_confidence = maybe\nsteady_clip_gamma = 0\n",
                      &messages),
      "a", envOf({}), &messages);
  EXPECT_FLOAT_EQ(bad.params.steadyFootprint, steadyxr::core::Params{}.steadyFootprint);
  EXPECT_TRUE(bad.params.steadyConfidence);
  EXPECT_FLOAT_EQ(bad.params.steadyClipGamma, steadyxr::core::Params{}.steadyClipGamma);
  EXPECT_TRUE(mentions(messages, "steady_clip_gamma", "0"));
  EXPECT_TRUE(mentions(messages, "steady_footprint", "0.5"));
  EXPECT_TRUE(mentions(messages, "steady_confidence", "maybe"));
}

// The example file the package installs (layer/xr/steadyxr.conf.example) is read as the layer reads
// it, as shipped and with every commented "# key = value" line switched on: an example with a wrong
// key or value would teach users a setting the layer refuses.
TEST(Config, TheShippedExampleParsesWithEveryCommentedSettingOn) {
  std::string error;
  const std::optional<std::string> example = readConfigFile(STEADYXR_EXAMPLE_CONFIG, &error);
  ASSERT_TRUE(example.has_value()) << error;
  std::vector<std::string> messages;
  resolveConfig(parseConfigText(*example, &messages), "HelloXR", envOf({}), &messages);
  EXPECT_TRUE(messages.empty()) << (messages.empty() ? "" : messages[0]);

  const std::regex commentedSetting(R"(^# ([a-z0-9_]+ = .*)$)");
  std::istringstream lines(*example);
  std::string line, uncommented;
  int switchedOn = 0;
  while (std::getline(lines, line)) {
    std::smatch m;
    if (std::regex_match(line, m, commentedSetting)) {
      line = m[1].str();
      ++switchedOn;
    }
    uncommented += line + "\n";
  }
  EXPECT_GE(switchedOn, 10);
  messages.clear();
  const Config c = resolveConfig(parseConfigText(uncommented, &messages), "HelloXR", envOf({}), &messages);
  EXPECT_TRUE(messages.empty()) << (messages.empty() ? "" : messages[0]);
  // The HUD profile under [HelloXR] (README, "Profiles for kinds of app").
  EXPECT_EQ(c.profile, "hud");
  EXPECT_FLOAT_EQ(c.params.steadyBlurBudgetPx2, 0.0104f);
  EXPECT_TRUE(c.params.steadyClipHoldsCurrent);
}

// A profile counts as set where it is named: it wins over keys of less specific places and loses
// to keys of the same or a more specific place, and a profile named in a more specific place (an
// app's section, the environment) replaces a less specific one.
TEST(Config, ProfilesApplyWhereTheyAreNamed) {
  const steadyxr::core::Params defaults;
  std::vector<std::string> messages;
  const auto resolve = [&](const std::string& text, const std::map<std::string, std::string>& env) {
    messages.clear();
    return resolveConfig(parseConfigText(text, &messages), "app", envOf(env), &messages);
  };
  // Each profile's own values are ones the layer takes (profiles are applied without messages).
  for (const char* name : {"default", "hud", "world-only", "noisy"}) {
    const auto settings = profileSettings(name);
    ASSERT_TRUE(settings.has_value()) << name;
    for (const ProfileSetting& p : *settings)
      EXPECT_EQ(checkSetting(p.key, p.value), "") << name << ": " << p.key;
  }

  Config c = resolve("[app]\nprofile = hud\n", {});
  EXPECT_TRUE(messages.empty()) << (messages.empty() ? "" : messages[0]);
  EXPECT_EQ(c.profile, "hud");
  EXPECT_FLOAT_EQ(c.params.steadyBlurBudgetPx2, 0.0104f);
  EXPECT_TRUE(c.params.steadyClipHoldsCurrent);
  EXPECT_FALSE(c.params.steadyClipCurvatureCentredGated);
  EXPECT_EQ(resolve("[other]\nprofile = hud\n", {}).profile, "default");  // another app's section
  c = resolve("[app]\nprofile = noisy\n", {});
  EXPECT_EQ(c.profile, "noisy");
  EXPECT_TRUE(c.params.steadyNoiseEstimate);
  EXPECT_TRUE(c.params.steadyNoiseResidualOverTime);
  EXPECT_TRUE(c.params.steadyNoiseChangeTest);

  // A profile in the app's section wins over the global part's keys and loses to the section's.
  c = resolve(
      "steady_blur_budget_px2 = 0.05\nsteady_alpha_floor = 0.125\n[app]\nprofile = HUD\n"
      "steady_clip_holds_current = 0\n",
      {});
  EXPECT_EQ(c.profile, "hud");
  EXPECT_FLOAT_EQ(c.params.steadyBlurBudgetPx2, 0.0104f);
  EXPECT_FLOAT_EQ(c.params.steadyAlphaFloor, 0.125f);  // a key the profile does not set stays
  EXPECT_FALSE(c.params.steadyClipHoldsCurrent);
  // In the global part, the profile loses to the same part's keys, wherever the line is.
  c = resolve("steady_blur_budget_px2 = 0.05\nprofile = hud\n", {});
  EXPECT_FLOAT_EQ(c.params.steadyBlurBudgetPx2, 0.05f);
  EXPECT_TRUE(c.params.steadyClipHoldsCurrent);

  // The environment's profile replaces the file's (hud's keys are not applied), its keys still win.
  c = resolve("profile = hud\n",
              {{"STEADYXR_PROFILE", "world-only"}, {"STEADYXR_STEADY_CLIP_HOLDS_CURRENT", "1"}});
  EXPECT_EQ(c.profile, "world-only");
  EXPECT_TRUE(c.params.steadyClipCurvatureCentredGated);
  EXPECT_FALSE(c.params.steadyHeadLockedSwitch);  // round 42: no head-locked content to find
  EXPECT_FLOAT_EQ(c.params.steadyBlurBudgetPx2, defaults.steadyBlurBudgetPx2);
  EXPECT_TRUE(c.params.steadyClipHoldsCurrent);

  // A name that is no profile: said in the user's words, and the default is used.
  c = resolve("profile = hud\n[app]\nprofile = cinema\n", {});
  EXPECT_EQ(c.profile, "default");
  EXPECT_FLOAT_EQ(c.params.steadyBlurBudgetPx2, defaults.steadyBlurBudgetPx2);
  EXPECT_TRUE(mentions(messages, "profile = cinema", "default, hud, world-only or noisy"));
  EXPECT_NE(checkSetting("profile", "cinema"), "");
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

// A temporary folder, removed with everything in it.
class TempDir {
 public:
  TempDir() {
    std::string t = (std::filesystem::temp_directory_path() / "steadyxr-config-XXXXXX").string();
    path_ = ::mkdtemp(t.data());
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  std::string file(const std::string& name, const std::string& content) const {
    const std::string p = path_ + "/" + name;
    std::ofstream(p, std::ios::binary) << content;
    return p;
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

TEST(ConfigHardening, DirectoryIsRejectedAndNotAnnounced) {
  TempDir dir;
  std::vector<std::string> messages;
  const Config c = loadConfig("app", envOf({{"STEADYXR_CONFIG", dir.path()}}), &messages);
  EXPECT_TRUE(mentions(messages, dir.path(), "not a regular file (a directory)"));
  EXPECT_TRUE(c.configFile.empty());  // never announced as the config
  EXPECT_EQ(c.method, "default");
}

TEST(ConfigHardening, DeviceAndPipeAreRejectedWithoutReading) {
  std::vector<std::string> messages;
  const Config c = loadConfig("app", envOf({{"STEADYXR_CONFIG", "/dev/zero"}}), &messages);
  EXPECT_TRUE(mentions(messages, "/dev/zero", "not a regular file (a device, pipe or socket)"));
  EXPECT_TRUE(c.configFile.empty());
  TempDir dir;
  const std::string fifo = dir.path() + "/fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  messages.clear();
  std::string error;
  // Opening a FIFO without O_NONBLOCK would wait for a writer: the test would hang.
  EXPECT_FALSE(readConfigFile(fifo, &error).has_value());
  EXPECT_NE(error.find("not a regular file"), std::string::npos) << error;
}

TEST(ConfigHardening, SizeCap) {
  TempDir dir;
  // Exactly the limit is read; one byte more is refused with a clear message.
  std::string atLimit = "method = taa\n";
  atLimit += std::string(kMaxConfigBytes - atLimit.size() - 1, '#') + "\n";
  ASSERT_EQ(atLimit.size(), kMaxConfigBytes);
  std::vector<std::string> messages;
  Config c = loadConfig("app", envOf({{"STEADYXR_CONFIG", dir.file("ok.conf", atLimit)}}), &messages);
  EXPECT_TRUE(messages.empty());
  EXPECT_EQ(c.method, "taa");
  const std::string big = dir.file("big.conf", atLimit + "#");
  c = loadConfig("app", envOf({{"STEADYXR_CONFIG", big}}), &messages);
  EXPECT_EQ(c.method, "default");
  EXPECT_TRUE(c.configFile.empty());
  EXPECT_TRUE(mentions(messages, big, "larger than the limit of 1048576 bytes"));
}

TEST(ConfigHardening, WarningsAreCappedWithACount) {
  std::string text;
  for (int i = 0; i < 100000; ++i) text += "bad line " + std::to_string(i) + "\n";
  text += "w_min = x\n";
  std::vector<std::string> messages;
  const ConfigText t = parseConfigText(text, &messages);
  resolveConfig(t, "app", envOf({}), &messages);
  ASSERT_EQ(messages.size(), kMaxConfigMessages + 2);  // 10, the parser's count, the resolver's count
  EXPECT_TRUE(mentions(messages, "line 1:", "expected key = value"));
  EXPECT_EQ(messages[kMaxConfigMessages], "config: 99990 more problems not shown");
  EXPECT_EQ(messages[kMaxConfigMessages + 1], "config: 1 more problem not shown");
}

TEST(ConfigHardening, DuplicateKeysAreWarnedAndTheLaterWins) {
  std::vector<std::string> messages;
  const ConfigText t =
      parseConfigText("method = taa\nw_min = 0.2\n[app]\nmethod = fxaa\nMETHOD = none\n", &messages);
  ASSERT_EQ(messages.size(), 1u);  // the global and the section's method are different settings
  EXPECT_EQ(messages[0],
            "config: line 5: method is set again in [app] (also on line 4); the later value 'none' wins");
  EXPECT_EQ(resolveConfig(t, "app", envOf({}), &messages).method, "none");
  messages.clear();
  parseConfigText("method = taa\nmethod = hmtaa\n", &messages);
  EXPECT_TRUE(mentions(messages, "line 2: method is set again (also on line 1)", "'hmtaa' wins"));
}

TEST(ConfigHardening, MessagesUseTheUsersKeysAndValues) {
  std::vector<std::string> messages;
  Config c = resolveConfig(parseConfigText("w_lb = abc\n", &messages), "app", envOf({}), &messages);
  ASSERT_EQ(messages.size(), 1u);
  EXPECT_EQ(messages[0],
            "config: w_lb = abc (config file): expected a number in [0, 1]; using the default 0.1");
  messages.clear();
  c = resolveConfig(parseConfigText("w_lb = 0.5\n", &messages), "app", envOf({}), &messages);
  EXPECT_TRUE(mentions(messages, "w_lb = 0.5 is above w_min = 0.3", "using w_lb = 0.3"));
  EXPECT_FLOAT_EQ(c.params.wLowerBound, 0.3f);
  messages.clear();
  resolveConfig({}, "app", envOf({{"STEADYXR_W_LB", "abc"}}), &messages);
  EXPECT_TRUE(mentions(messages, "STEADYXR_W_LB = abc", "(environment)"));
  // Values the core would refuse are refused here, in the user's words (never "taaAlpha").
  messages.clear();
  c = resolveConfig(parseConfigText("taa_alpha = 0\nreset_angle_deg = 0\n", &messages), "app", envOf({}),
                    &messages);
  EXPECT_TRUE(mentions(messages, "taa_alpha = 0", "(0, 1]"));
  EXPECT_TRUE(mentions(messages, "reset_angle_deg = 0", "(0, 180]"));
  for (const auto& m : messages) EXPECT_EQ(m.find("taaAlpha"), std::string::npos) << m;
  core::Params checked;
  EXPECT_EQ(core::validate(c.params, &checked), "");
}

TEST(ConfigHardening, NumbersAreDecimalOnly) {
  for (const char* bad : {"0x10", "1,5", "inf", "nan", "+-1", "1e", " ", "25deg"}) {
    std::vector<std::string> messages;
    const Config c = resolveConfig({}, "a", envOf({{"STEADYXR_H_MAX", bad}}), &messages);
    EXPECT_FLOAT_EQ(c.params.hMaxDegPerSec, core::Params{}.hMaxDegPerSec) << bad;
    EXPECT_EQ(messages.size(), 1u) << bad;
  }
  for (const char* bad : {"0x10", "1.5", "-1", "+3"}) {
    std::vector<std::string> messages;
    resolveConfig({}, "a", envOf({{"STEADYXR_DUMP_FRAMES", bad}}), &messages);
    EXPECT_EQ(messages.size(), 1u) << bad;
  }
  std::vector<std::string> messages;
  const Config c = resolveConfig(parseConfigText("h_max = 1e1\nw_min = .25\ndump_frames = 010\n", &messages),
                                 "a", envOf({}), &messages);
  EXPECT_TRUE(messages.empty());
  EXPECT_FLOAT_EQ(c.params.hMaxDegPerSec, 10.0f);
  EXPECT_FLOAT_EQ(c.params.wMin, 0.25f);
  EXPECT_EQ(c.dumpFrames, 10u);  // decimal, not octal
}

TEST(ConfigReload, GoodEditIsTakenBadEditIsRefused) {
  TempDir dir;
  const auto env = envOf({{"STEADYXR_LOG_LEVEL", "loud"}});  // a bad variable must not block reloads
  std::vector<std::string> messages;
  const std::string path = dir.file("s.conf", "method = taa\n[app]\nenabled = 0\n[other]\nw_min = 2\n");
  std::optional<Config> c = reloadConfig(path, "app", env, &messages);
  ASSERT_TRUE(c.has_value()) << (messages.empty() ? "" : messages[0]);
  EXPECT_EQ(c->method, "taa");
  EXPECT_FALSE(c->enabled);
  EXPECT_EQ(c->configFile, path);
  for (const char* edit : {"method = sharpen\n", "method = taa\nmethd = none\n", "[app\n", "w_lb = 0.9\n"}) {
    messages.clear();
    dir.file("s.conf", edit);
    EXPECT_FALSE(reloadConfig(path, "app", env, &messages).has_value()) << edit;
    EXPECT_FALSE(messages.empty()) << edit;
  }
  messages.clear();
  EXPECT_FALSE(reloadConfig(dir.path() + "/gone.conf", "app", env, &messages).has_value());
  EXPECT_TRUE(mentions(messages, "gone.conf", "cannot be opened"));
}

TEST(ConfigReload, EnvironmentStillWinsAndHardDisables) {
  TempDir dir;
  std::vector<std::string> messages;
  const std::string path = dir.file("s.conf", "method = taa\nenabled = 1\n");
  auto c =
      reloadConfig(path, "app", envOf({{"STEADYXR_METHOD", "none"}, {"STEADYXR_DISABLE", "1"}}), &messages);
  ASSERT_TRUE(c.has_value());
  EXPECT_EQ(c->method, "none");
  EXPECT_FALSE(c->enabled);
  EXPECT_TRUE(c->environmentDisabled);
  EXPECT_FALSE(resolveConfig(parseConfigText("enabled = 0\n", &messages), "a", envOf({}), &messages)
                   .environmentDisabled);  // the file's switch stays a live one
}

TEST(ConfigReload, CheckSetting) {
  EXPECT_EQ(checkSetting("method", "taa"), "");
  EXPECT_EQ(checkSetting("W_LB", " 0.05 "), "");
  EXPECT_NE(checkSetting("method", "sharpen").find("method = sharpen"), std::string::npos);
  EXPECT_NE(checkSetting("colour", "red").find("unknown key 'colour'"), std::string::npos);
  EXPECT_NE(checkSetting("h_max", "0x10").find("h_max = 0x10"), std::string::npos);
}

TEST(Config, UserConfigPath) {
  EXPECT_EQ(userConfigPath(envOf({{"XDG_CONFIG_HOME", "/x"}, {"HOME", "/h"}})), "/x/steadyxr/steadyxr.conf");
  EXPECT_EQ(userConfigPath(envOf({{"HOME", "/h"}})), "/h/.config/steadyxr/steadyxr.conf");
  EXPECT_EQ(userConfigPath(envOf({})), "");
}

}  // namespace
}  // namespace steadyxr::layer
