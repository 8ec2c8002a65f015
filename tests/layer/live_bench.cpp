// What live control costs the app's frame loop: the per-frame check of the config watcher (one
// non-blocking read of the inotify descriptor), LiveConfig's poll and takeUpdate with nothing
// changed, and one status file rewrite (about once a second). Prints medians; no assertions.
//   steadyxr_live_bench [iterations]
#include "config_watch.h"
#include "status_file.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace {

using steadyxr::layer::Config;
using steadyxr::layer::ConfigWatcher;
using steadyxr::layer::LiveConfig;
using steadyxr::layer::Logger;
using steadyxr::layer::LogLevel;
using steadyxr::layer::StatusFile;

template <typename F>
double medianNs(int iterations, F&& f) {
  std::vector<double> ns;
  ns.reserve(static_cast<size_t>(iterations));
  for (int i = 0; i < iterations; ++i) {
    const auto a = std::chrono::steady_clock::now();
    f();
    const auto b = std::chrono::steady_clock::now();
    ns.push_back(std::chrono::duration<double, std::nano>(b - a).count());
  }
  std::nth_element(ns.begin(), ns.begin() + static_cast<std::ptrdiff_t>(ns.size() / 2), ns.end());
  return ns[ns.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  const int iterations = argc > 1 ? std::max(1, std::atoi(argv[1])) : 20000;
  std::string t = (std::filesystem::temp_directory_path() / "steadyxr-live-bench-XXXXXX").string();
  const std::string root = ::mkdtemp(t.data());
  const std::string conf = root + "/steadyxr.conf";
  std::ofstream(conf) << "method = taa\n";

  std::string error;
  auto watcher = ConfigWatcher::create(conf, &error);
  if (!watcher) {
    std::fprintf(stderr, "cannot watch: %s\n", error.c_str());
    return 1;
  }
  const double watch = medianNs(iterations, [&] { (void)watcher->changed(); });

  Logger log(LogLevel::Error, "");
  const auto env = [&](const std::string& name) -> std::optional<std::string> {
    if (name == "STEADYXR_CONFIG") return conf;
    return std::nullopt;
  };
  std::vector<std::string> messages;
  LiveConfig live(steadyxr::layer::loadConfig("bench", env, &messages), "bench", env, log);
  uint64_t seen = 0;
  const double poll = medianNs(iterations, [&] {
    live.poll();
    (void)live.takeUpdate(&seen);
  });

  auto status = StatusFile::create(root, &error);
  const std::string text(600, 'x');  // about the size of a real status file
  const double write =
      status ? medianNs(std::min(iterations, 2000), [&] { status->write(text, &error); }) : -1.0;
  status.reset();

  std::printf("live control per frame, median of %d: watcher check %.0f ns, poll + takeUpdate %.0f ns\n",
              iterations, watch, poll);
  std::printf("status file rewrite (about once a second), median: %.1f us in %s\n", write / 1000.0,
              root.c_str());
  std::filesystem::remove_all(root);
  return 0;
}
