// The run's one-line progress bar with an estimate of the time left (stderr).
#pragma once

#include <chrono>
#include <cstdio>
#include <string>

namespace steadyxr::eval {

class Progress {
 public:
  Progress(bool enabled, int total)
      : enabled_(enabled), total_(total), start_(std::chrono::steady_clock::now()) {}
  void update(int done, const std::string& what) {
    if (!enabled_) return;
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const double eta = done > 0 ? elapsed * (total_ - done) / done : 0.0;
    const int width = 30, filled = total_ > 0 ? width * done / total_ : width;
    std::fprintf(stderr, "\r[%s%s] %3d%% %-38.38s %5.0fs left ", std::string(filled, '#').c_str(),
                 std::string(width - filled, ' ').c_str(), total_ > 0 ? 100 * done / total_ : 100,
                 what.c_str(), eta);
    std::fflush(stderr);
  }
  void finish() {
    if (enabled_) std::fprintf(stderr, "\n");
  }

 private:
  bool enabled_;
  int total_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace steadyxr::eval
