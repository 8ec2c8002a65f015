// The session's live parts: settings from config file edits, applied between frames, and the
// status file that `steadyxr status` lists. Kept apart from the frame path (session_frame.cpp).
#include "session.h"

#include <unistd.h>
#include <chrono>
#include <cstdio>
#include <sstream>

namespace steadyxr::layer {
namespace {

// How often the status file is rewritten (the issue asks for about once a second): a rename in
// the user's tmpfs, far below a frame's cost at that rate.
constexpr int64_t kStatusPeriodNs = 1'000'000'000;

int64_t steadyNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

int64_t unixMs() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace

void Session::applyLiveConfig() {
  LiveConfig* live = instance_->live.get();
  if (live == nullptr) return;
  live->poll();
  std::optional<Config> cfg = live->takeUpdate(&liveGeneration_);
  if (!cfg) return;
  // The filter and the dumper belong to the frame work (frameMutex_); the flags to mutex_.
  std::scoped_lock lock(frameMutex_, mutex_);
  if (shutDown_) return;
  const Config& before = appliedConfig_ ? *appliedConfig_ : instance_->config;
  const bool wasEnabled = liveEnabled_;
  liveEnabled_ = cfg->enabled;
  if (filter_) {
    // The method name was checked by the config; a change of temporal method resets the
    // history inside the filter (setParams), and so does switching back on after a pause.
    if (std::optional<core::Params> params = core::applyMethodName(cfg->method, cfg->params)) {
      jitter_ = cfg->jitter && undoesJitter(params->temporal);
      stats_.jitter = stats_.jitter || jitter_;
      params->jitteredInput = jitter_;
      filter_->setParams(*params);
    }
    if (liveEnabled_ && !wasEnabled) filter_->reset();
  }
  if (cfg->dumpDir != before.dumpDir || cfg->dumpFrames != before.dumpFrames) {
    dumper_ = ImageDumper(cfg->dumpDir, cfg->dumpFrames);  // the next N filtered frames
  }
  appliedConfig_ = std::move(cfg);
  statusDue_ = true;
}

std::string Session::statusText() const {
  const Config& cfg = appliedConfig_ ? *appliedConfig_ : instance_->config;
  std::ostringstream os;
  os << "pid=" << ::getpid() << "\n";
  if (auto ticks = processStartTicks(::getpid())) os << "process_start_ticks=" << *ticks << "\n";
  os << "app=" << instance_->applicationName << "\n";
  os << "updated_unix_ms=" << unixMs() << "\n";
  os << "enabled=" << (liveEnabled_ ? 1 : 0) << "\n";
  os << "method=" << cfg.method << "\n";
  os << "profile=" << cfg.profile << "\n";
  if (filter_) os << "passes=" << core::methodName(filter_->params()) << "\n";
  os << "state="
     << (!vulkanSession_ ? "not-vulkan"
         : !filtering_   ? "passing-through"
         : !liveEnabled_ ? "disabled"
                         : "filtering")
     << "\n";
  const char* pose = "runtime";
  if (cfg.poseSource == PoseSourceKind::Imu) pose = imu_ ? "imu" : "runtime (imu unavailable)";
  os << "pose_source=" << pose << "\n";
  os << "config=" << (cfg.configFile.empty() ? "(none)" : cfg.configFile) << "\n";
  if (instance_->live) {
    os << "config_watched=" << instance_->live->watchedPath() << "\n";
    os << "config_generation=" << instance_->live->generation() << "\n";
    os << "config_applied_unix_ms=" << instance_->live->appliedUnixMs() << "\n";
  }
  const uint64_t warmingUp = stats_.passed[static_cast<size_t>(PassReason::Compiling)];
  uint64_t passedTotal = 0;
  for (uint64_t n : stats_.passed) passedTotal += n;
  os << "frames_filtered=" << stats_.framesFiltered << "\n";
  os << "frames_passed_through=" << passedTotal - warmingUp << "\n";
  for (size_t r = 0; r < stats_.passed.size(); ++r) {
    if (stats_.passed[r] == 0 || r == static_cast<size_t>(PassReason::Compiling)) continue;
    os << "passed_" << toString(static_cast<PassReason>(r)) << "=" << stats_.passed[r] << "\n";
  }
  os << "frames_warming_up=" << warmingUp << "\n";
  os << "frames_warming_up_late=" << stats_.warmingUpLate << "\n";
  os << "frames_disabled=" << stats_.framesDisabled << "\n";
  os << "frames_empty=" << stats_.framesEmpty << "\n";
  os << "render_size_changes=" << stats_.renderSize.framesResized << "\n";
  os << "history_kept_resized=" << stats_.renderSize.historyKeptResized << "\n";
  os << "images_reallocated=" << stats_.renderSize.imagesReallocated << "\n";
  os << "image_memory_bytes=" << stats_.imageMemoryBytes << "\n";
  if (stats_.timingFrames > 0) {
    const double n = static_cast<double>(stats_.timingFrames);
    char buf[200];
    std::snprintf(buf, sizeof buf,
                  "gpu_ms_temporal=%.3f\ngpu_ms_stereo=%.3f\ngpu_ms_other=%.3f\ngpu_ms_total=%.3f\n",
                  stats_.temporalMs / n, stats_.stereoMs / n, stats_.otherMs / n, stats_.totalMs / n);
    os << buf;
  }
  if (stats_.imuFrames + stats_.imuFallbackFrames > 0) {
    os << "imu_frames=" << stats_.imuFrames << "\nimu_fallback=" << stats_.imuFallbackFrames << "\n";
  }
  return os.str();
}

void Session::publishStatus() {
  if (!instance_->status) return;
  const int64_t now = steadyNs();
  if (!statusDue_ && now - lastStatusNs_ < kStatusPeriodNs) return;
  std::string text;
  {
    std::lock_guard lock(mutex_);
    if (shutDown_) return;
    text = statusText();
    statusDue_ = false;
  }
  lastStatusNs_ = now;
  std::string error;  // the write happens outside the session's lock
  if (!instance_->status->write(text, &error))
    instance_->log->once(LogLevel::Warn, "status-write", "status: " + error);
}

}  // namespace steadyxr::layer
