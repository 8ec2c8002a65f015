// The layer's logger: one per layer instance (no global logger state). Lines go to standard
// error or a file, prefixed so they stand out in the host application's output.
#pragma once

#include "config.h"

#include <cstdio>
#include <memory>
#include <mutex>
#include <set>
#include <string>

namespace steadyxr::layer {

class Logger {
 public:
  Logger(LogLevel level, const std::string& path);
  void log(LogLevel level, const std::string& message);
  // Logs the first time `key` is seen, then stays quiet: failures repeat every frame.
  void once(LogLevel level, const std::string& key, const std::string& message);
  bool enabled(LogLevel level) const { return level <= level_; }

 private:
  struct FileCloser {
    void operator()(FILE* f) const { std::fclose(f); }
  };
  LogLevel level_;
  std::unique_ptr<FILE, FileCloser> file_;
  std::mutex mutex_;
  std::set<std::string> seen_;
};

}  // namespace steadyxr::layer
