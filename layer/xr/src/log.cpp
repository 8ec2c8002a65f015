#include "log.h"

namespace steadyxr::layer {

Logger::Logger(LogLevel level, const std::string& path) : level_(level) {
  if (!path.empty()) file_.reset(std::fopen(path.c_str(), "a"));
}

void Logger::log(LogLevel level, const std::string& message) {
  if (!enabled(level)) return;
  std::lock_guard lock(mutex_);
  FILE* out = file_ ? file_.get() : stderr;
  std::fprintf(out, "[steadyxr] %.*s: %s\n", static_cast<int>(toString(level).size()), toString(level).data(),
               message.c_str());
  std::fflush(out);
}

void Logger::once(LogLevel level, const std::string& key, const std::string& message) {
  {
    std::lock_guard lock(mutex_);
    if (!seen_.insert(key).second) return;
  }
  log(level, message);
}

}  // namespace steadyxr::layer
