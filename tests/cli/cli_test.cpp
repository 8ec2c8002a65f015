// The `steadyxr` command-line tool on real files: every verb, bad input (a clear message and the
// config untouched), and that what it writes the layer's reload accepts.
#include "cli.h"
#include "status_file.h"

#include <gtest/gtest.h>

#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

namespace steadyxr::cli {
namespace {

namespace fs = std::filesystem;

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string t = (fs::temp_directory_path() / "steadyxr-cli-XXXXXX").string();
    root_ = ::mkdtemp(t.data());
    ::mkdir((root_ + "/run").c_str(), 0700);
    vars_ = {{"XDG_CONFIG_HOME", root_ + "/config"}, {"XDG_RUNTIME_DIR", root_ + "/run"}, {"HOME", root_}};
  }
  void TearDown() override { fs::remove_all(root_); }

  int cli(std::vector<std::string> args) {
    out_.str("");
    err_.str("");
    const auto vars = vars_;
    const layer::EnvLookup env = [vars](const std::string& name) -> std::optional<std::string> {
      auto it = vars.find(name);
      return it == vars.end() ? std::nullopt : std::optional<std::string>(it->second);
    };
    return run(args, env, out_, err_);
  }
  std::string conf() const { return root_ + "/config/steadyxr/steadyxr.conf"; }
  std::string read(const std::string& p) const {
    std::ifstream in(p, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  }
  void write(const std::string& p, const std::string& text) const {
    fs::create_directories(fs::path(p).parent_path());
    std::ofstream(p, std::ios::binary) << text;
  }
  // What the layer makes of the file for `app` on a live reload (nullopt: it would refuse it).
  std::optional<layer::Config> layerSees(const std::string& app) const {
    std::vector<std::string> messages;
    const auto noEnv = [](const std::string&) -> std::optional<std::string> { return std::nullopt; };
    return layer::reloadConfig(conf(), app, noEnv, &messages);
  }
  std::vector<std::string> filesIn(const std::string& dir) const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
    return names;
  }

  std::string root_;
  std::map<std::string, std::string> vars_;
  std::ostringstream out_;
  std::ostringstream err_;
};

TEST_F(Cli, EnableAndDisableCreateTheFileAndSections) {
  ASSERT_EQ(cli({"disable"}), 0) << err_.str();
  EXPECT_EQ(read(conf()), "enabled = 0\n");
  EXPECT_FALSE(layerSees("any")->enabled);
  ASSERT_EQ(cli({"enable", "--app", "hello_xr"}), 0) << err_.str();
  EXPECT_EQ(read(conf()), "enabled = 0\n\n[hello_xr]\nenabled = 1\n");
  EXPECT_TRUE(layerSees("hello_xr")->enabled);
  EXPECT_FALSE(layerSees("other")->enabled);
  ASSERT_EQ(cli({"enable"}), 0);
  EXPECT_EQ(read(conf()), "enabled = 1\n\n[hello_xr]\nenabled = 1\n");
  EXPECT_NE(out_.str().find("set enabled = 1 in " + conf()), std::string::npos) << out_.str();
}

TEST_F(Cli, SetGlobalAndPerApp) {
  ASSERT_EQ(cli({"set", "method=taa", "w_min=0.2"}), 0) << err_.str();
  ASSERT_EQ(cli({"set", "--app", "hello_xr", "method=none"}), 0) << err_.str();
  ASSERT_EQ(cli({"set", "--app=Hello XR", "METHOD = hmtaa+stereo"}), 0) << err_.str();
  EXPECT_EQ(layerSees("hello_xr")->method, "none");
  EXPECT_EQ(layerSees("Hello XR")->method, "hmtaa+stereo");
  EXPECT_EQ(layerSees("other")->method, "taa");
  EXPECT_FLOAT_EQ(layerSees("other")->params.wMin, 0.2f);
}

TEST_F(Cli, EditsInPlaceKeepingCommentsAndDroppingDuplicates) {
  write(
      conf(),
      "# mine\nmethod = taa  # was fxaa\nlog_level = info\nmethod = vtaa\n\n[app]\n# per app\nw_min = 0.2\n");
  ASSERT_EQ(cli({"set", "method=hybrid", "dump_frames=3"}), 0) << err_.str();
  EXPECT_EQ(read(conf()),
            "# mine\nlog_level = info\nmethod = hybrid\ndump_frames = 3\n\n[app]\n# per app\nw_min = 0.2\n");
  ASSERT_EQ(cli({"set", "--app", "app", "method=none"}), 0);
  ASSERT_EQ(cli({"set", "--app", "app", "w_min=0.25"}), 0);
  EXPECT_EQ(read(conf()),
            "# mine\nlog_level = info\nmethod = hybrid\ndump_frames = 3\n\n[app]\n# per app\n"
            "w_min = 0.25\nmethod = none\n");
  write(conf(), "method = taa  # note\n");
  ASSERT_EQ(cli({"set", "method=fxaa"}), 0);
  EXPECT_EQ(read(conf()), "method = fxaa  # note\n");
  // A global key goes before the first section even when there is no global setting yet.
  write(conf(), "# header\n[app]\nmethod = none\n");
  ASSERT_EQ(cli({"set", "method=taa"}), 0);
  EXPECT_EQ(read(conf()), "# header\nmethod = taa\n\n[app]\nmethod = none\n");
  EXPECT_EQ(layerSees("x")->method, "taa");
}

TEST_F(Cli, BadInputIsRefusedAndTheFileIsUntouched) {
  const std::string original = "method = taa\n[app]\nw_min = 0.2\n";
  write(conf(), original);
  struct stat before {};
  ASSERT_EQ(::stat(conf().c_str(), &before), 0);
  struct Case {
    std::vector<std::string> args;
    int rc;
    std::string message;
  };
  const Case cases[] = {
      {{"set", "w_lb=abc"}, 1, "w_lb = abc (command line): expected a number in [0, 1]"},
      {{"set", "method=sharpen"}, 1, "method = sharpen (command line): expected none, fxaa"},
      {{"set", "h_max=0x10"}, 1, "h_max = 0x10"},
      {{"set", "colour=red"}, 1, "unknown key 'colour'"},
      {{"set", "method=taa", "taa_alpha=0"}, 1, "taa_alpha = 0 (command line): expected a number in (0, 1]"},
      {{"set", "--app", "app", "w_lb=0.25"}, 1, "w_lb = 0.25 is above w_min = 0.2"},  // whole-file check
      {{"set", "method"}, 2, "'method' is not KEY=VALUE"},
      {{"set", "=taa"}, 2, "'=taa' is not KEY=VALUE"},
      {{"set"}, 2, "set needs KEY=VALUE"},
      {{"set", "dump_dir=/tmp/a #b"}, 1, "cannot hold a line break or ' #'"},
      {{"set", "--app", " padded", "method=taa"}, 2, "bad app name ' padded'"},
      {{"set", "--app", "two\nlines", "method=taa"}, 2, "bad app name"},
      {{"enable", "--app"}, 2, "--app needs the app's name"},
      {{"enable", "now"}, 2, "enable takes no arguments"},
      {{"unset", "colour"}, 1, "unknown key 'colour'"},
      {{"show", "extra"}, 2, "show takes no arguments"},
      {{"frobnicate"}, 2, "unknown command 'frobnicate'"},
      {{}, 2, "usage: steadyxr"},
  };
  for (const Case& c : cases) {
    EXPECT_EQ(cli(c.args), c.rc) << c.message;
    EXPECT_NE(err_.str().find(c.message), std::string::npos)
        << "want '" << c.message << "' in: " << err_.str();
    EXPECT_EQ(read(conf()), original) << c.message;
  }
  struct stat after {};
  ASSERT_EQ(::stat(conf().c_str(), &after), 0);
  EXPECT_EQ(before.st_ino, after.st_ino);  // never replaced
  EXPECT_EQ(filesIn(root_ + "/config/steadyxr"), std::vector<std::string>{"steadyxr.conf"});  // no temp files
}

TEST_F(Cli, UnreadableConfigIsNotReplaced) {
  fs::create_directories(conf());  // a directory where the file should be
  EXPECT_EQ(cli({"enable"}), 1);
  EXPECT_NE(err_.str().find("is not a regular file (a directory); not changed"), std::string::npos)
      << err_.str();
  EXPECT_TRUE(fs::is_directory(conf()));
  fs::remove(conf());
  write(conf(), std::string(layer::kMaxConfigBytes + 1, '#'));
  EXPECT_EQ(cli({"enable"}), 1);
  EXPECT_NE(err_.str().find("larger than the limit"), std::string::npos) << err_.str();
  EXPECT_EQ(fs::file_size(conf()), layer::kMaxConfigBytes + 1);
}

TEST_F(Cli, WritesThroughASymlinkAndKeepsTheMode) {
  const std::string target = root_ + "/dotfiles/steadyxr.conf";
  write(target, "method = taa\n");
  ::chmod(target.c_str(), 0600);
  fs::create_directories(fs::path(conf()).parent_path());
  fs::create_symlink(target, conf());
  ASSERT_EQ(cli({"set", "method=none"}), 0) << err_.str();
  EXPECT_TRUE(fs::is_symlink(conf()));
  EXPECT_EQ(read(target), "method = none\n");
  struct stat st {};
  ASSERT_EQ(::stat(target.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  EXPECT_EQ(filesIn(root_ + "/dotfiles"), std::vector<std::string>{"steadyxr.conf"});
}

TEST_F(Cli, ConfigPathChoice) {
  vars_["STEADYXR_CONFIG"] = root_ + "/env.conf";
  ASSERT_EQ(cli({"disable"}), 0);
  EXPECT_EQ(read(root_ + "/env.conf"), "enabled = 0\n");
  ASSERT_EQ(cli({"--config", root_ + "/opt.conf", "set", "method=taa"}), 0);
  EXPECT_EQ(read(root_ + "/opt.conf"), "method = taa\n");
  EXPECT_FALSE(fs::exists(conf()));
}

TEST_F(Cli, Unset) {
  write(conf(), "method = taa\nw_min = 0.2\n[app]\nmethod = none\n");
  ASSERT_EQ(cli({"unset", "--app", "app", "method"}), 0) << err_.str();
  EXPECT_EQ(read(conf()), "method = taa\nw_min = 0.2\n[app]\n");
  ASSERT_EQ(cli({"unset", "method", "w_min"}), 0);
  EXPECT_EQ(read(conf()), "[app]\n");
  EXPECT_EQ(layerSees("app")->method, "default");
}

// A profile is set as any key, refused by name when it is none, and shown with what it sets.
TEST_F(Cli, ProfilesAreSetCheckedAndShown) {
  ASSERT_EQ(cli({"set", "--app", "game", "profile=hud"}), 0) << err_.str();
  EXPECT_EQ(read(conf()), "[game]\nprofile = hud\n");
  EXPECT_FLOAT_EQ(layerSees("game")->params.steadyBlurBudgetPx2, 0.0104f);
  EXPECT_EQ(layerSees("other")->profile, "default");
  ASSERT_EQ(cli({"show", "--app", "game"}), 0) << err_.str();
  EXPECT_NE(out_.str().find(
                "  profile = hud (sets steady_blur_budget_px2 = 0.0104, steady_clip_holds_current = 1)\n"),
            std::string::npos)
      << out_.str();
  EXPECT_EQ(cli({"set", "profile=cinema"}), 1);
  EXPECT_NE(err_.str().find("expected default, hud, world-only or noisy"), std::string::npos) << err_.str();
  EXPECT_EQ(read(conf()), "[game]\nprofile = hud\n");
}

TEST_F(Cli, Show) {
  write(conf(), "method = taa\nw_min = 9\n[hello_xr]\nmethod = none\n");
  vars_["STEADYXR_LOG_LEVEL"] = "debug";
  ASSERT_EQ(cli({"show", "--app", "hello_xr"}), 0) << err_.str();
  const std::string o = out_.str();
  EXPECT_NE(o.find("config file: " + conf()), std::string::npos) << o;
  EXPECT_NE(o.find("problem: config: w_min = 9 (config file)"), std::string::npos) << o;
  EXPECT_NE(o.find("in effect for [hello_xr]"), std::string::npos) << o;
  EXPECT_NE(o.find("  method = none\n"), std::string::npos) << o;
  EXPECT_NE(o.find("  log_level = debug\n"), std::string::npos) << o;
  EXPECT_NE(o.find("note: STEADYXR_LOG_LEVEL=debug is set in this shell"), std::string::npos) << o;
  fs::remove(conf());
  ASSERT_EQ(cli({"show"}), 0);
  EXPECT_NE(out_.str().find("(does not exist: defaults)"), std::string::npos) << out_.str();
}

TEST_F(Cli, HelpForEveryVerb) {
  ASSERT_EQ(cli({"--help"}), 0);
  for (const char* verb : {"enable", "disable", "set", "unset", "show", "status"}) {
    EXPECT_NE(out_.str().find(std::string("  ") + verb), std::string::npos) << verb;
  }
  EXPECT_EQ(cli({"set", "--help"}), 0);
  EXPECT_NE(out_.str().find("usage: steadyxr"), std::string::npos);
}

TEST_F(Cli, StatusListsLiveInstancesAndRemovesStaleOnes) {
  const std::string folder = root_ + "/run/steadyxr";
  ASSERT_EQ(cli({"status"}), 0);
  EXPECT_NE(out_.str().find("no running steadyxr instances"), std::string::npos);
  ::mkdir(folder.c_str(), 0700);
  const long self = ::getpid();
  const uint64_t ticks = layer::processStartTicks(self).value();
  write(folder + "/" + std::to_string(self) + "-1.status",
        "pid=" + std::to_string(self) + "\nprocess_start_ticks=" + std::to_string(ticks) +
            "\napp=hello_xr\nstate=filtering\nenabled=1\nmethod=default\npasses=hybrid+stereo\n"
            "pose_source=runtime\nframes_filtered=120\nframes_passed_through=2\npassed_format=2\n"
            "frames_warming_up=3\nframes_warming_up_late=1\nframes_disabled=0\n"
            "gpu_ms_temporal=2.900\ngpu_ms_stereo=2.100\ngpu_ms_other=0.200\ngpu_ms_total=5.200\n"
            "config=/c.conf\nconfig_generation=2\n");
  // The same pid but another start time: the pid was reused after the writer died.
  write(folder + "/" + std::to_string(self) + "-2.status",
        "pid=" + std::to_string(self) + "\nprocess_start_ticks=" + std::to_string(ticks + 1) + "\napp=old\n");
  // A process that has exited.
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ::waitpid(child, nullptr, 0);
  write(folder + "/" + std::to_string(child) + "-1.status", "pid=" + std::to_string(child) + "\napp=gone\n");
  ASSERT_EQ(cli({"status"}), 0) << err_.str();
  const std::string o = out_.str();
  EXPECT_NE(o.find("hello_xr (pid " + std::to_string(self) +
                   "): filtering, method default (hybrid+stereo), enabled 1, pose runtime"),
            std::string::npos)
      << o;
  EXPECT_NE(o.find("frames: 120 filtered, 2 passed through (format=2), 3 warming up (1 after filtering "
                   "began), 0 disabled"),
            std::string::npos)
      << o;
  EXPECT_NE(o.find("temporal 2.900, stereo 2.100, other 0.200, total 5.200"), std::string::npos) << o;
  EXPECT_EQ(o.find("gone"), std::string::npos) << o;
  EXPECT_EQ(o.find("old"), std::string::npos) << o;
  EXPECT_NE(o.find("removed 2 stale status files"), std::string::npos) << o;
  EXPECT_EQ(filesIn(folder), std::vector<std::string>{std::to_string(self) + "-1.status"});
  vars_.erase("XDG_RUNTIME_DIR");
  EXPECT_EQ(cli({"status"}), 1);
  EXPECT_NE(err_.str().find("XDG_RUNTIME_DIR is not set"), std::string::npos);
}

// What the CLI accepts, the layer accepts: every key with a good value goes through `set` and
// the layer's reload takes the file without a problem.
TEST_F(Cli, EverythingItWritesTheLayerAccepts) {
  const std::map<std::string, std::string> good = {{"enabled", "0"},
                                                   {"method", "vtaa+stereo"},
                                                   {"pose_source", "imu"},
                                                   {"imu_device", "hid:1209:0001"},
                                                   {"log_level", "debug"},
                                                   {"log_file", "/tmp/l.log"},
                                                   {"dump_frames", "4"},
                                                   {"dump_dir", "/tmp/d"},
                                                   {"jitter", "on"},
                                                   {"sample_count", "2"},
                                                   {"history_filter", "catmull-rom"},
                                                   {"history_format", "rgba8"},
                                                   {"profile", "world-only"},
                                                   {"taa_alpha", "0.2"},
                                                   {"taa_clip_gamma", "1.5"},
                                                   {"h_max", "30"},
                                                   {"w_min", "0.4"},
                                                   {"w_lb", "0.05"},
                                                   {"vtaa_alpha_min", "0.1"},
                                                   {"stereo_far_m", "20"},
                                                   {"stereo_depth_tolerance", "0.05"},
                                                   {"stereo_beta_min", "0.5"},
                                                   {"reset_angle_deg", "30"},
                                                   {"reset_translation_m", "0.5"},
                                                   {"steady_alpha_floor", "0.1"},
                                                   {"steady_blur_budget_px2", "0.2"},
                                                   {"steady_footprint", "0.05"},
                                                   {"steady_clip_gamma", "1"},
                                                   {"steady_output_hold", "0.5"},
                                                   {"steady_nearest_depth_m", "1"},
                                                   {"steady_confidence", "off"},
                                                   {"steady_clip_rejects", "no"},
                                                   {"steady_interpolated", "1"},
                                                   {"steady_footprint_encoded", "off"},
                                                   {"steady_history_blur_per_axis", "off"},
                                                   {"steady_blur_noise_trade", "off"},
                                                   {"steady_clip_holds_current", "on"},
                                                   {"steady_noise_estimate", "on"},
                                                   {"steady_noise_residual_over_time", "0"},
                                                   {"steady_noise_change_test", "off"},
                                                   {"steady_gain_compensation", "off"},
                                                   {"steady_gain_relights_admitted", "off"},
                                                   {"steady_unexplained_frame_resets", "off"},
                                                   {"steady_resolved_edges", "off"},
                                                   {"steady_head_locked_switch", "off"},
                                                   {"steady_clip_curvature", "on"},
                                                   {"steady_clip_curvature_centred", "on"},
                                                   {"steady_clip_curvature_centred_gated", "on"},
                                                   {"steady_clip_quant_srgb", "on"},
                                                   {"stereo_inverse_variance", "off"},
                                                   {"stereo_tap_curvature", "off"},
                                                   {"stereo_clip_gamma_after_steady", "2"}};
  for (const std::string& key : layer::knownConfigKeys()) {
    ASSERT_TRUE(good.count(key)) << "no good value for " << key << " in this test";
    ASSERT_EQ(cli({"set", "--app", "a", key + "=" + good.at(key)}), 0) << key << ": " << err_.str();
  }
  std::vector<std::string> messages;
  const auto noEnv = [](const std::string&) -> std::optional<std::string> { return std::nullopt; };
  const std::optional<layer::Config> c = layer::reloadConfig(conf(), "a", noEnv, &messages);
  ASSERT_TRUE(c.has_value()) << (messages.empty() ? "" : messages[0]);
  EXPECT_EQ(c->method, "vtaa+stereo");
  EXPECT_FLOAT_EQ(c->params.wLowerBound, 0.05f);
}

}  // namespace
}  // namespace steadyxr::cli
