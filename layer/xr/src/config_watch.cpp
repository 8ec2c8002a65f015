#include "config_watch.h"

#include <sys/inotify.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <set>
#include <system_error>

namespace steadyxr::layer {
namespace {

// Events that mean "the file now has new content": a writer closed it, or a finished file was
// renamed into place. IN_MODIFY and IN_CREATE are left out on purpose: they fire before the
// writer is done (`echo x > new.conf` creates an empty file first).
constexpr uint32_t kFileEvents = IN_CLOSE_WRITE | IN_MOVED_TO;
// The watched folder itself went away (removed or renamed): watch its parent again.
constexpr uint32_t kFolderGone = IN_DELETE_SELF | IN_MOVE_SELF | IN_IGNORED;

std::pair<std::string, std::string> splitPath(const std::string& path) {
  const std::filesystem::path p(path);
  std::string folder = p.parent_path().string();
  return {folder.empty() ? std::string(".") : folder, p.filename().string()};
}

int64_t unixMsNow() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace

std::unique_ptr<ConfigWatcher> ConfigWatcher::create(const std::string& path, std::string* error) {
  const int fd = ::inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
  if (fd < 0) {
    if (error) *error = "inotify_init1 failed (" + std::generic_category().message(errno) + ")";
    return nullptr;
  }
  // A symlinked config (dotfile managers) changes where the link points: watch the target.
  std::error_code ec;
  const std::filesystem::path resolved = std::filesystem::canonical(path, ec);
  std::unique_ptr<ConfigWatcher> w(new ConfigWatcher(fd, ec ? path : resolved.string()));
  if (!w->watchFolder()) {
    if (error)
      *error = "'" + w->folder_ + "' and its parent '" + w->parent_ + "' cannot be watched (missing?)";
    return nullptr;
  }
  return w;
}

ConfigWatcher::ConfigWatcher(int fd, std::string path) : fd_(fd), path_(std::move(path)) {
  std::tie(folder_, name_) = splitPath(path_);
  std::tie(parent_, folderName_) = splitPath(folder_);
}

ConfigWatcher::~ConfigWatcher() {
  ::close(fd_);  // drops every watch
}

bool ConfigWatcher::watchFolder() {
  folderWatch_ = ::inotify_add_watch(fd_, folder_.c_str(), kFileEvents | IN_DELETE_SELF | IN_MOVE_SELF);
  if (folderWatch_ >= 0) return true;
  if (parentWatch_ < 0) parentWatch_ = ::inotify_add_watch(fd_, parent_.c_str(), IN_CREATE | IN_MOVED_TO);
  return parentWatch_ >= 0;
}

bool ConfigWatcher::changed() {
  // inotify_event is variable-length; the buffer is aligned for it (inotify(7)).
  alignas(inotify_event) char buffer[4096];
  bool hit = false;
  bool rearm = false;
  for (;;) {
    const ssize_t n = ::read(fd_, buffer, sizeof buffer);
    if (n <= 0) break;  // EAGAIN: nothing (more) happened
    for (ssize_t off = 0; off < n;) {
      inotify_event event;
      std::memcpy(&event, buffer + off, sizeof event);
      const char* name = buffer + off + sizeof(inotify_event);
      const bool named = event.len > 0;
      if (event.wd == folderWatch_ && named && (event.mask & kFileEvents) && name_ == name) hit = true;
      if (event.mask & IN_Q_OVERFLOW) hit = true;  // events were lost: read the file to be sure
      if (event.wd == folderWatch_ && (event.mask & kFolderGone)) rearm = true;
      if (event.wd == parentWatch_ && named && folderName_ == name) rearm = true;
      off += static_cast<ssize_t>(sizeof(inotify_event) + event.len);
    }
  }
  if (rearm) {
    if (folderWatch_ >= 0) ::inotify_rm_watch(fd_, folderWatch_);
    folderWatch_ = -1;
    watchFolder();
    // The folder may have appeared with the file already in it (mkdir, then a rename, before
    // the new watch existed).
    std::error_code ec;
    if (folderWatch_ >= 0 && std::filesystem::exists(path_, ec)) hit = true;
  }
  return hit;
}

std::string configWatchPath(const Config& config, const EnvLookup& env) {
  if (!config.configFile.empty()) return config.configFile;
  if (auto p = env("STEADYXR_CONFIG"); p && !p->empty()) return *p;
  return userConfigPath(env);
}

std::string describeChanges(const std::map<std::string, std::string>& before,
                            const std::map<std::string, std::string>& after, std::string* restartOnly) {
  static const std::set<std::string> kRestartOnly = {"pose_source", "imu_device", "log_level", "log_file",
                                                     "jitter"};
  std::set<std::string> keys;
  for (const auto& kv : before) keys.insert(kv.first);
  for (const auto& kv : after) keys.insert(kv.first);
  std::string live;
  std::string later;
  for (const std::string& key : keys) {
    const auto a = before.find(key);
    const auto b = after.find(key);
    const std::string from = a == before.end() ? "(default)" : a->second;
    const std::string to = b == after.end() ? "(default)" : b->second;
    if (from == to) continue;
    std::string& list = kRestartOnly.count(key) ? later : live;
    list += (list.empty() ? "" : ", ") + key + " " + from + " -> " + to;
  }
  if (restartOnly) *restartOnly = later;
  return live;
}

LiveConfig::LiveConfig(Config initial, std::string applicationName, EnvLookup env, Logger& log)
    : current_(std::move(initial)),
      applicationName_(std::move(applicationName)),
      env_(std::move(env)),
      log_(log) {
  // The settings the instance started with, to tell later edits apart key by key.
  ConfigText text;
  if (!current_.configFile.empty()) {
    if (std::optional<std::string> content = readConfigFile(current_.configFile, nullptr)) {
      text = parseConfigText(*content, nullptr);
    }
  }
  settings_ = effectiveSettings(text, applicationName_, env_);
  const std::string path = configWatchPath(current_, env_);
  if (path.empty()) {
    log_.log(LogLevel::Info, "config: no config file to watch (neither XDG_CONFIG_HOME nor HOME is set)");
    return;
  }
  std::string error;
  watcher_ = ConfigWatcher::create(path, &error);
  if (!watcher_) {
    log_.log(LogLevel::Warn,
             "config: cannot watch '" + path + "' (" + error + "); edits apply at the next start");
  } else {
    log_.log(LogLevel::Debug, "config: watching '" + watcher_->path() + "' for edits");
  }
}

void LiveConfig::poll() {
  if (watcher_ && watcher_->changed()) reload();
}

void LiveConfig::reload() {
  std::vector<std::string> messages;
  std::map<std::string, std::string> settings;
  std::optional<Config> next = reloadConfig(watcher_->path(), applicationName_, env_, &messages, &settings);
  std::lock_guard lock(mutex_);
  if (!next) {
    for (const std::string& m : messages) log_.log(LogLevel::Warn, m);
    log_.log(LogLevel::Warn,
             "config: '" + watcher_->path() + "' not applied; keeping the last good settings");
    return;
  }
  std::string restartOnly;
  const std::string changes = describeChanges(settings_, settings, &restartOnly);
  settings_ = std::move(settings);
  // Read once at start: what the instance was created with stays (see describeChanges).
  next->poseSource = current_.poseSource;
  next->imuDevice = current_.imuDevice;
  next->logLevel = current_.logLevel;
  next->logFile = current_.logFile;
  next->jitter = current_.jitter;
  next->environmentDisabled = current_.environmentDisabled;
  if (!restartOnly.empty()) {
    log_.log(LogLevel::Warn, "config: " + restartOnly + " take effect at the app's next start");
  }
  if (changes.empty()) return;
  current_ = *next;
  ++generation_;
  appliedUnixMs_ = unixMsNow();
  log_.log(LogLevel::Info, "config: applied " + changes + " from '" + watcher_->path() + "'");
}

std::optional<Config> LiveConfig::takeUpdate(uint64_t* seen) {
  std::lock_guard lock(mutex_);
  if (*seen == generation_) return std::nullopt;
  *seen = generation_;
  return current_;
}

uint64_t LiveConfig::generation() const {
  std::lock_guard lock(mutex_);
  return generation_;
}

int64_t LiveConfig::appliedUnixMs() const {
  std::lock_guard lock(mutex_);
  return appliedUnixMs_;
}

std::string LiveConfig::watchedPath() const {
  return watcher_ ? watcher_->path() : std::string();
}

}  // namespace steadyxr::layer
