// Live configuration: the layer notices edits of its config file while the app runs and applies
// `enabled`, `method` and the pass parameters within a frame or two.
#pragma once

#include "config.h"
#include "log.h"

#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

namespace steadyxr::layer {

// Watches one file for being written or replaced, through inotify on its folder: editors save
// by writing a new file and renaming it over the old one, and a watch on the file itself would
// stay on the old inode. When the folder does not exist yet (no config written so far), its
// parent is watched for the folder to appear. changed() is one non-blocking read() that fails
// with EAGAIN when nothing happened: cheap enough to call every frame, and no polling of the disk.
class ConfigWatcher {
 public:
  // nullptr (and *error) when the file cannot be watched (no inotify, no parent folder).
  static std::unique_ptr<ConfigWatcher> create(const std::string& path, std::string* error);
  ~ConfigWatcher();
  ConfigWatcher(const ConfigWatcher&) = delete;
  ConfigWatcher& operator=(const ConfigWatcher&) = delete;

  // True when the file was closed after writing, or moved or created into place, since the last
  // call. Never blocks.
  bool changed();
  const std::string& path() const { return path_; }

 private:
  ConfigWatcher(int fd, std::string path);
  bool watchFolder();  // the file's folder, else its parent for the folder to appear

  int fd_;
  std::string path_;
  std::string folder_;      // the file's folder
  std::string name_;        // the file's name in it
  std::string parent_;      // the folder's parent
  std::string folderName_;  // the folder's name in its parent
  int folderWatch_ = -1;
  int parentWatch_ = -1;
};

// The file the layer watches: the one it read, else the one $STEADYXR_CONFIG names, else the
// per-user file (so that `steadyxr enable` writing it for the first time is noticed).
std::string configWatchPath(const Config& config, const EnvLookup& env);

// The settings of one layer instance, kept up to date with its config file. poll() runs on the
// app's frame thread once per frame; a good edit becomes a new generation, a bad one is logged
// and the last good settings stay.
class LiveConfig {
 public:
  LiveConfig(Config initial, std::string applicationName, EnvLookup env, Logger& log);
  // Checks the watcher (when there is one) and reloads the file when it changed.
  void poll();
  // The current settings when their generation differs from *seen (then *seen is updated).
  std::optional<Config> takeUpdate(uint64_t* seen);
  uint64_t generation() const;
  int64_t appliedUnixMs() const;  // when the current generation was loaded (0: at start)
  std::string watchedPath() const;

 private:
  void reload();

  mutable std::mutex mutex_;
  Config current_;
  std::map<std::string, std::string> settings_;  // effectiveSettings() of the file last read
  std::string applicationName_;
  EnvLookup env_;
  Logger& log_;
  std::unique_ptr<ConfigWatcher> watcher_;
  uint64_t generation_ = 0;
  int64_t appliedUnixMs_ = 0;
};

// What changed between two effectiveSettings(), in the user's keys and values ("enabled 1 -> 0,
// method taa -> none, w_min (default) -> 0.5"); `restartOnly` gets the changed keys that take
// effect only at the app's next start (pose_source, imu_device, log_level, log_file, jitter).
std::string describeChanges(const std::map<std::string, std::string>& before,
                            const std::map<std::string, std::string>& after, std::string* restartOnly);

}  // namespace steadyxr::layer
