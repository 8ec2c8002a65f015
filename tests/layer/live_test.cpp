// Live control without an app: the inotify watcher on real files (editor-style rename, in-place
// write, a folder made later), LiveConfig's reload policy, and the status file.
#include "config_watch.h"
#include "status_file.h"

#include <gtest/gtest.h>

#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

namespace steadyxr::layer {
namespace {

namespace fs = std::filesystem;

class Live : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string t = (fs::temp_directory_path() / "steadyxr-live-XXXXXX").string();
    root_ = ::mkdtemp(t.data());
  }
  void TearDown() override { fs::remove_all(root_); }
  static void write(const std::string& p, const std::string& text) {
    std::ofstream(p, std::ios::binary) << text;
  }
  // As editors save: a new file renamed over the old one.
  static void saveByRename(const std::string& p, const std::string& text) {
    write(p + ".swp", text);
    fs::rename(p + ".swp", p);
  }
  static std::string read(const std::string& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  }
  std::string root_;
};

TEST_F(Live, WatcherSeesRenameOnSaveAndInPlaceWrites) {
  const std::string conf = root_ + "/steadyxr.conf";
  write(conf, "method = taa\n");
  std::string error;
  auto w = ConfigWatcher::create(conf, &error);
  ASSERT_TRUE(w) << error;
  EXPECT_FALSE(w->changed());  // nothing yet, and it returns at once
  saveByRename(conf, "method = none\n");
  EXPECT_TRUE(w->changed());
  EXPECT_FALSE(w->changed());      // consumed
  write(conf, "method = fxaa\n");  // truncate and write in place: one event at close
  EXPECT_TRUE(w->changed());
  write(root_ + "/other.conf", "x\n");  // other files in the folder do not count
  saveByRename(root_ + "/other.conf", "y\n");
  EXPECT_FALSE(w->changed());
}

TEST_F(Live, WatcherWaitsForTheFolderToAppear) {
  const std::string conf = root_ + "/steadyxr/steadyxr.conf";  // no folder yet
  std::string error;
  auto w = ConfigWatcher::create(conf, &error);
  ASSERT_TRUE(w) << error;
  EXPECT_FALSE(w->changed());
  fs::create_directory(root_ + "/steadyxr");
  saveByRename(conf, "enabled = 0\n");  // both before the watcher looks again
  EXPECT_TRUE(w->changed());
  saveByRename(conf, "enabled = 1\n");  // now through the folder's own watch
  EXPECT_TRUE(w->changed());
  EXPECT_FALSE(ConfigWatcher::create(root_ + "/no/such/folder/x.conf", &error));
  EXPECT_NE(error.find("cannot be watched"), std::string::npos) << error;
}

TEST_F(Live, WatcherFollowsASymlinkedConfig) {
  fs::create_directory(root_ + "/dotfiles");
  const std::string target = root_ + "/dotfiles/steadyxr.conf";
  write(target, "method = taa\n");
  fs::create_symlink(target, root_ + "/steadyxr.conf");
  std::string error;
  auto w = ConfigWatcher::create(root_ + "/steadyxr.conf", &error);
  ASSERT_TRUE(w) << error;
  saveByRename(target, "method = none\n");
  EXPECT_TRUE(w->changed());
}

TEST_F(Live, GoodEditsApplyBadOnesKeepTheLastGoodSettings) {
  const std::string conf = root_ + "/steadyxr.conf";
  write(conf, "method = taa\n");
  const std::string logPath = root_ + "/layer.log";
  Logger log(LogLevel::Info, logPath);
  const EnvLookup env = [&](const std::string& name) -> std::optional<std::string> {
    if (name == "STEADYXR_CONFIG") return conf;
    return std::nullopt;
  };
  std::vector<std::string> messages;
  LiveConfig live(loadConfig("app", env, &messages), "app", env, log);
  uint64_t seen = 0;
  live.poll();
  EXPECT_FALSE(live.takeUpdate(&seen));

  saveByRename(conf, "method = none\nenabled = 0\nw_min = 0.5\n");
  live.poll();
  std::optional<Config> c = live.takeUpdate(&seen);
  ASSERT_TRUE(c);
  EXPECT_EQ(c->method, "none");
  EXPECT_FALSE(c->enabled);
  EXPECT_FLOAT_EQ(c->params.wMin, 0.5f);
  EXPECT_EQ(seen, 1u);
  EXPECT_GT(live.appliedUnixMs(), 0);
  EXPECT_NE(read(logPath).find(
                "config: applied enabled (default) -> 0, method taa -> none, w_min (default) -> 0.5"),
            std::string::npos)
      << read(logPath);

  saveByRename(conf, "method = sharpen\nenabled = 1\n");  // a bad edit: nothing of it applies
  live.poll();
  EXPECT_FALSE(live.takeUpdate(&seen));
  EXPECT_NE(read(logPath).find("method = sharpen (config file)"), std::string::npos);
  EXPECT_NE(read(logPath).find("not applied; keeping the last good settings"), std::string::npos);

  saveByRename(conf, "method = none\nenabled = 0\nw_min = 0.5\npose_source = imu\n");  // restart-only key
  live.poll();
  EXPECT_FALSE(live.takeUpdate(&seen));
  EXPECT_NE(read(logPath).find("pose_source (default) -> imu take effect at the app's next start"),
            std::string::npos)
      << read(logPath);

  saveByRename(conf, "method = hmtaa\npose_source = imu\n");  // a live key and a restart-only one
  live.poll();
  c = live.takeUpdate(&seen);
  ASSERT_TRUE(c);
  EXPECT_NE(read(logPath).find("config: applied enabled 0 -> (default), method none -> hmtaa, w_min 0.5 -> "
                               "(default)"),
            std::string::npos)
      << read(logPath);
  EXPECT_EQ(c->method, "hmtaa");
  EXPECT_TRUE(c->enabled);
  EXPECT_EQ(c->poseSource, PoseSourceKind::Runtime);  // as the instance started
  EXPECT_EQ(live.generation(), 2u);
  saveByRename(conf, "method = hmtaa\npose_source = imu\nstereo_beta_min = 0.6\n");  // one tunable alone
  live.poll();
  c = live.takeUpdate(&seen);
  ASSERT_TRUE(c);
  EXPECT_FLOAT_EQ(c->params.stereoBetaMin, 0.6f);
  uint64_t fresh = UINT64_MAX;  // a session created later gets the current settings
  EXPECT_EQ(live.takeUpdate(&fresh)->method, "hmtaa");
}

TEST_F(Live, StatusFileIsPrivateAtomicAndRemoved) {
  std::string error;
  EXPECT_FALSE(StatusFile::create("", &error));
  EXPECT_NE(error.find("XDG_RUNTIME_DIR is not set"), std::string::npos);
  std::string path;
  {
    auto status = StatusFile::create(root_, &error);
    ASSERT_TRUE(status) << error;
    path = status->path();
    EXPECT_EQ(fs::path(path).parent_path(), fs::path(root_) / "steadyxr");
    EXPECT_TRUE(fs::path(path).filename().string().starts_with(std::to_string(::getpid()) + "-"));
    ASSERT_TRUE(status->write("pid=1\napp=a\n", &error)) << error;
    ASSERT_TRUE(status->write("pid=1\napp=b\n", &error)) << error;
    EXPECT_EQ(read(path), "pid=1\napp=b\n");
    struct stat st {};
    ASSERT_EQ(::stat(path.c_str(), &st), 0);
    EXPECT_EQ(st.st_mode & 0777, 0600u);
    ASSERT_EQ(::stat((root_ + "/steadyxr").c_str(), &st), 0);
    EXPECT_EQ(st.st_mode & 0777, 0700u);
    EXPECT_EQ(std::distance(fs::directory_iterator(root_ + "/steadyxr"), fs::directory_iterator()), 1);
    auto second = StatusFile::create(root_, &error);  // a second instance in the process
    ASSERT_TRUE(second);
    EXPECT_NE(second->path(), path);
  }
  EXPECT_FALSE(fs::exists(path));  // removed with the instance
  // A folder that is a symlink (someone else's) is not used.
  const std::string other = root_ + "/other";
  fs::create_directory(other);
  fs::remove_all(root_ + "/steadyxr");
  fs::create_directory_symlink(other, root_ + "/steadyxr");
  EXPECT_FALSE(StatusFile::create(root_, &error));
  EXPECT_NE(error.find("is not a folder of this user"), std::string::npos) << error;
}

TEST(StatusFileParts, ProcessStartTicksAndParse) {
  const auto self = processStartTicks(::getpid());
  ASSERT_TRUE(self);
  EXPECT_GT(*self, 0u);
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ::waitpid(child, nullptr, 0);
  EXPECT_FALSE(processStartTicks(child));
  const auto s = parseStatus("pid=3\napp=a=b\nnoise\n=x\n");
  EXPECT_EQ(s.size(), 2u);
  EXPECT_EQ(s.at("app"), "a=b");
}

}  // namespace
}  // namespace steadyxr::layer
