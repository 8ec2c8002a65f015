// The IMU pose source: a reader thread (hidapi or a non-HID transport) -> ReportParser -> Fusion
// -> PoseHistory, sampled by the OpenXR layer's `imu` pose source through PoseSource::stateAt.
//
// Spec strings for openImuPoseSource():
//   hid:VID:PID            hidapi, first device with that vendor/product id (hex, e.g. hid:1209:0001)
//   hidraw:/dev/hidrawN    hidapi, by device path
//   fifo:/path             framed reports (hid_report.h) from a named pipe the emulator writes
//   socket:/path           Unix SOCK_SEQPACKET socket the emulator listens on, one report per message
//   file:/path             framed reports from a file, read as fast as possible, then the thread ends
// Optional suffix "?clock=host" or "?clock=device": the time domain of stateAt(). Default: host
// CLOCK_MONOTONIC for hid/hidraw/fifo/socket, device clock for file (a recording has no host time).
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "steadyxr/imu/fusion.h"
#include "steadyxr/imu/hid_report.h"
#include "steadyxr/imu/pose_source.h"

namespace steadyxr::imu {

// Where reports come from. read() waits at most timeoutMs.
class ReportTransport {
 public:
  enum class Result { kReport, kTimeout, kEnd, kError };
  virtual ~ReportTransport() = default;
  virtual Result read(std::vector<uint8_t>* report, int timeoutMs) = 0;
  virtual std::string describe() const = 0;
  virtual uint64_t garbageBytes() const { return 0; }
};

std::unique_ptr<ReportTransport> openHidTransport(uint16_t vid, uint16_t pid, std::string* error);
std::unique_ptr<ReportTransport> openHidPathTransport(const std::string& path, std::string* error);
std::unique_ptr<ReportTransport> openFifoTransport(const std::string& path, std::string* error);
std::unique_ptr<ReportTransport> openFileTransport(const std::string& path, std::string* error);
std::unique_ptr<ReportTransport> openSocketTransport(const std::string& path, std::string* error);

enum class TimeDomain { kHostMonotonic, kDevice };

struct ImuStats {
  hid::ParserStats parser;
  uint64_t fusionRejected = 0;
  uint64_t historyOutOfOrder = 0;
  uint64_t clockResets = 0;
  bool running = false;
  std::string lastError;
  uint64_t streamEnds = 0;  // the transport ended or failed (each one logged)
  uint64_t reconnects = 0;  // reopened after an end
};

// Reopens a live source after its stream ended (a device unplugged, the emulator restarted).
using ReopenTransport = std::function<std::unique_ptr<ReportTransport>(std::string* error)>;
// Where the reader's lines go (the layer's logger); empty: nowhere.
using ImuLog = std::function<void(const std::string& line)>;

// Reconnect attempts after a live stream ends, each after the next of these delays (doubling
// from 100 ms: a replugged USB device re-enumerates in well under a second; ~6 s in all), then
// the reader gives up and stateAt() has no new data (the layer falls back to runtime poses).
inline constexpr std::chrono::milliseconds kReconnectDelays[] = {
    std::chrono::milliseconds(100), std::chrono::milliseconds(200),  std::chrono::milliseconds(400),
    std::chrono::milliseconds(800), std::chrono::milliseconds(1600), std::chrono::milliseconds(3200)};

int64_t monotonicNowNs();

class ImuPoseSource final : public PoseSource {
 public:
  ImuPoseSource(std::unique_ptr<ReportTransport> transport, TimeDomain domain,
                const FusionParams& fusion = {}, const PoseHistory::Params& history = {},
                ReopenTransport reopen = {}, ImuLog log = {});
  ~ImuPoseSource() override;  // stops and joins the reader thread
  ImuPoseSource(const ImuPoseSource&) = delete;
  ImuPoseSource& operator=(const ImuPoseSource&) = delete;

  std::optional<HeadState> stateAt(int64_t timeNs) const override;
  TimeDomain timeDomain() const { return domain_; }
  ImuStats stats() const;
  // For tests and tools: waits until the reader has fused `count` samples or stopped.
  bool waitForSamples(uint64_t count, std::chrono::milliseconds timeout) const;
  const PoseHistory& history() const { return history_; }

 private:
  void run();
  bool reconnect();  // bounded retry of reopen_; true with transport_ replaced
  void sleepUnlessStopped(std::chrono::milliseconds d) const;

  std::unique_ptr<ReportTransport> transport_;
  ReopenTransport reopen_;
  ImuLog log_;
  TimeDomain domain_;
  FusionParams fusionParams_;
  PoseHistory history_;
  mutable std::mutex statsMu_;
  ImuStats stats_;
  std::atomic<uint64_t> fused_{0};
  std::atomic<bool> stop_{false};
  std::atomic<bool> running_{true};
  std::thread thread_;
};

// Parses a spec (see the top of this file) and starts reading. nullptr and *error on failure.
// Live sources (all but file:) reconnect after their stream ends (kReconnectDelays); the end,
// each reconnect and giving up are one line each to `log`.
std::unique_ptr<ImuPoseSource> openImuPoseSource(const std::string& spec, std::string* error,
                                                 ImuLog log = {});

}  // namespace steadyxr::imu
