#include "steadyxr/imu/imu_pose_source.h"

#include <cerrno>
#include <cstring>
#include <ctime>

#include <fcntl.h>
#include <hidapi.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

namespace steadyxr::imu {
namespace {

void setError(std::string* error, const std::string& msg) {
  if (error) *error = msg;
}

std::string errnoText(const std::string& what) {
  return what + ": " + std::strerror(errno);
}

class UniqueFd {
 public:
  explicit UniqueFd(int fd = -1) : fd_(fd) {}
  ~UniqueFd() {
    if (fd_ >= 0) ::close(fd_);
  }
  UniqueFd(const UniqueFd&) = delete;
  UniqueFd& operator=(const UniqueFd&) = delete;
  int get() const { return fd_; }

 private:
  int fd_;
};

// Waits for input; false on timeout (or EINTR, which the caller treats as a timeout).
bool waitReadable(int fd, int timeoutMs) {
  pollfd p{fd, POLLIN, 0};
  return ::poll(&p, 1, timeoutMs) > 0;
}

class HidapiTransport final : public ReportTransport {
 public:
  HidapiTransport(hid_device* dev, std::string what) : dev_(dev), what_(std::move(what)) {}
  ~HidapiTransport() override { hid_close(dev_); }
  Result read(std::vector<uint8_t>* report, int timeoutMs) override {
    report->resize(256);
    const int n = hid_read_timeout(dev_, report->data(), report->size(), timeoutMs);
    if (n < 0) return Result::kError;
    if (n == 0) return Result::kTimeout;
    report->resize(static_cast<size_t>(n));
    return Result::kReport;
  }
  std::string describe() const override { return what_; }

 private:
  hid_device* dev_;
  std::string what_;
};

// FIFO and file: a byte stream of framed reports.
class StreamTransport final : public ReportTransport {
 public:
  StreamTransport(int fd, bool endAtEof, std::string what)
      : fd_(fd), endAtEof_(endAtEof), what_(std::move(what)) {}
  Result read(std::vector<uint8_t>* report, int timeoutMs) override {
    for (;;) {
      if (decoder_.next(report)) return Result::kReport;
      if (!endAtEof_ && !waitReadable(fd_.get(), timeoutMs)) return Result::kTimeout;
      uint8_t buf[4096];
      const ssize_t n = ::read(fd_.get(), buf, sizeof buf);
      if (n < 0) {
        if (errno == EINTR || errno == EAGAIN) return Result::kTimeout;
        return Result::kError;
      }
      if (n == 0) return endAtEof_ ? Result::kEnd : Result::kTimeout;
      decoder_.feed({buf, static_cast<size_t>(n)});
    }
  }
  std::string describe() const override { return what_; }
  uint64_t garbageBytes() const override { return decoder_.garbageBytes(); }

 private:
  UniqueFd fd_;
  bool endAtEof_;
  std::string what_;
  hid::FrameDecoder decoder_;
};

class SocketTransport final : public ReportTransport {
 public:
  SocketTransport(int fd, std::string what) : fd_(fd), what_(std::move(what)) {}
  Result read(std::vector<uint8_t>* report, int timeoutMs) override {
    if (!waitReadable(fd_.get(), timeoutMs)) return Result::kTimeout;
    report->resize(512);
    const ssize_t n = ::recv(fd_.get(), report->data(), report->size(), 0);
    if (n < 0) return errno == EINTR || errno == EAGAIN ? Result::kTimeout : Result::kError;
    if (n == 0) return Result::kEnd;
    report->resize(static_cast<size_t>(n));
    return Result::kReport;
  }
  std::string describe() const override { return what_; }

 private:
  UniqueFd fd_;
  std::string what_;
};

bool hidInit(std::string* error) {
  if (hid_init() != 0) {  // idempotent; hid_exit is left to the process (others may use hidapi)
    setError(error, "hid_init failed");
    return false;
  }
  return true;
}

}  // namespace

int64_t monotonicNowNs() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

std::unique_ptr<ReportTransport> openHidTransport(uint16_t vid, uint16_t pid, std::string* error) {
  if (!hidInit(error)) return nullptr;
  char what[64];
  std::snprintf(what, sizeof what, "hid:%04x:%04x", vid, pid);
  hid_device* dev = hid_open(vid, pid, nullptr);
  if (!dev) {
    setError(error, std::string("no HID device ") + what + " (or no permission on its hidraw node)");
    return nullptr;
  }
  return std::make_unique<HidapiTransport>(dev, what);
}

std::unique_ptr<ReportTransport> openHidPathTransport(const std::string& path, std::string* error) {
  if (!hidInit(error)) return nullptr;
  hid_device* dev = hid_open_path(path.c_str());
  if (!dev) {
    setError(error, "cannot open HID device '" + path + "'");
    return nullptr;
  }
  return std::make_unique<HidapiTransport>(dev, "hidraw:" + path);
}

std::unique_ptr<ReportTransport> openFifoTransport(const std::string& path, std::string* error) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    if (::mkfifo(path.c_str(), 0600) != 0) {
      setError(error, errnoText("mkfifo " + path));
      return nullptr;
    }
  } else if (!S_ISFIFO(st.st_mode)) {
    setError(error, "'" + path + "' exists and is not a FIFO");
    return nullptr;
  }
  // O_RDWR (Linux): never blocks in open() waiting for a writer and never sees EOF between writers.
  const int fd = ::open(path.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    setError(error, errnoText("open " + path));
    return nullptr;
  }
  return std::make_unique<StreamTransport>(fd, false, "fifo:" + path);
}

std::unique_ptr<ReportTransport> openFileTransport(const std::string& path, std::string* error) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    setError(error, errnoText("open " + path));
    return nullptr;
  }
  return std::make_unique<StreamTransport>(fd, true, "file:" + path);
}

std::unique_ptr<ReportTransport> openSocketTransport(const std::string& path, std::string* error) {
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  if (path.size() >= sizeof addr.sun_path) {
    setError(error, "socket path too long: " + path);
    return nullptr;
  }
  std::memcpy(addr.sun_path, path.c_str(), path.size() + 1);
  const int fd = ::socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0);
  if (fd < 0) {
    setError(error, errnoText("socket"));
    return nullptr;
  }
  auto t = std::make_unique<SocketTransport>(fd, "socket:" + path);
  if (::connect(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
    setError(error, errnoText("connect " + path));
    return nullptr;
  }
  return t;
}

ImuPoseSource::ImuPoseSource(std::unique_ptr<ReportTransport> transport, TimeDomain domain,
                             const FusionParams& fusion, const PoseHistory::Params& history,
                             ReopenTransport reopen, ImuLog log)
    : transport_(std::move(transport)),
      reopen_(std::move(reopen)),
      log_(std::move(log)),
      domain_(domain),
      fusionParams_(fusion),
      history_(history) {
  stats_.running = true;
  thread_ = std::thread([this] { run(); });
}

ImuPoseSource::~ImuPoseSource() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

std::optional<HeadState> ImuPoseSource::stateAt(int64_t timeNs) const {
  return history_.stateAt(timeNs);
}

ImuStats ImuPoseSource::stats() const {
  const std::lock_guard lock(statsMu_);
  ImuStats s = stats_;
  s.historyOutOfOrder = history_.outOfOrder();
  s.running = running_;
  return s;
}

bool ImuPoseSource::waitForSamples(uint64_t count, std::chrono::milliseconds timeout) const {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (fused_ < count && running_ && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  return fused_ >= count;
}

void ImuPoseSource::sleepUnlessStopped(std::chrono::milliseconds d) const {
  const auto until = std::chrono::steady_clock::now() + d;
  while (!stop_ && std::chrono::steady_clock::now() < until)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
}

bool ImuPoseSource::reconnect() {
  std::string error;
  for (const auto delay : kReconnectDelays) {
    sleepUnlessStopped(delay);
    if (stop_) return false;
    if (auto t = reopen_(&error)) {
      transport_ = std::move(t);
      if (log_) log_("imu: reconnected to " + transport_->describe());
      const std::lock_guard lock(statsMu_);
      ++stats_.reconnects;
      return true;
    }
  }
  if (log_) log_("imu: cannot reconnect (" + error + "); no more IMU data");
  return false;
}

void ImuPoseSource::run() {
  hid::ReportParser parser;
  Fusion fusion(fusionParams_);
  ClockMapper clock;
  std::vector<uint8_t> report;
  std::vector<hid::ImuSample> samples;
  std::vector<FusedSample> fused;
  std::string error;
  while (!stop_) {
    const auto result = transport_->read(&report, 50);
    if (result == ReportTransport::Result::kTimeout) continue;
    if (result == ReportTransport::Result::kEnd || result == ReportTransport::Result::kError) {
      error = (result == ReportTransport::Result::kEnd ? "end of stream on " : "read error on ") +
              transport_->describe();
      {
        const std::lock_guard lock(statsMu_);
        ++stats_.streamEnds;
      }
      if (log_) log_("imu: " + error + (reopen_ ? "; reconnecting" : ""));
      if (!reopen_ || !reconnect()) break;
      // Parser, fusion and clock mapping go on: the parser counts a sequence jump and the
      // clock mapper re-anchors on a timestamp jump (ClockMapper::resets), as for any gap.
      error.clear();
      continue;
    }
    const int64_t hostNow = monotonicNowNs();
    samples.clear();
    fused.clear();
    parser.parse(report, &samples);
    for (const auto& s : samples)
      if (fusion.update(s)) fused.push_back(fusion.state());
    if (!fused.empty()) {
      if (domain_ == TimeDomain::kHostMonotonic) {
        // The newest sample of the report was measured just before it arrived.
        const int64_t offset = clock.update(hostNow, fused.back().timeNs);
        for (auto& f : fused) f.timeNs += offset;
      }
      history_.push(fused);
      fused_ += fused.size();
    }
    const std::lock_guard lock(statsMu_);
    stats_.parser = parser.stats();
    stats_.parser.garbageBytes = transport_->garbageBytes();
    stats_.fusionRejected = fusion.rejectedSamples();
    stats_.clockResets = clock.resets();
  }
  const std::lock_guard lock(statsMu_);
  // A file's end is where a recording stops, not an error.
  stats_.lastError = error.rfind("end of stream on file:", 0) == 0 ? std::string() : error;
  running_ = false;
}

std::unique_ptr<ImuPoseSource> openImuPoseSource(const std::string& specIn, std::string* error, ImuLog log) {
  std::string spec = specIn;
  std::optional<TimeDomain> domain;
  if (const auto q = spec.find("?clock="); q != std::string::npos) {
    const std::string v = spec.substr(q + 7);
    if (v == "host")
      domain = TimeDomain::kHostMonotonic;
    else if (v == "device")
      domain = TimeDomain::kDevice;
    else {
      setError(error, "imu spec '" + specIn + "': clock must be host or device");
      return nullptr;
    }
    spec.resize(q);
  }
  const auto colon = spec.find(':');
  const std::string kind = spec.substr(0, colon);
  const std::string arg = colon == std::string::npos ? std::string() : spec.substr(colon + 1);
  std::unique_ptr<ReportTransport> t;
  TimeDomain fallback = TimeDomain::kHostMonotonic;
  if (kind == "hid") {
    unsigned vid = 0, pid = 0;
    char tail = 0;
    if (std::sscanf(arg.c_str(), "%x:%x%c", &vid, &pid, &tail) != 2 || vid > 0xFFFF || pid > 0xFFFF) {
      setError(error, "imu spec '" + specIn + "': expected hid:VID:PID in hex");
      return nullptr;
    }
    t = openHidTransport(static_cast<uint16_t>(vid), static_cast<uint16_t>(pid), error);
  } else if (kind == "hidraw" && !arg.empty()) {
    t = openHidPathTransport(arg, error);
  } else if (kind == "fifo" && !arg.empty()) {
    t = openFifoTransport(arg, error);
  } else if (kind == "socket" && !arg.empty()) {
    t = openSocketTransport(arg, error);
  } else if (kind == "file" && !arg.empty()) {
    t = openFileTransport(arg, error);
    fallback = TimeDomain::kDevice;
  } else {
    setError(error, "imu spec '" + specIn +
                        "': expected hid:VID:PID, hidraw:PATH, fifo:PATH, socket:PATH or file:PATH");
    return nullptr;
  }
  if (!t) return nullptr;
  PoseHistory::Params history;
  if (kind == "file") history.capacity = 1u << 17;  // a recording is sampled afterwards: keep ~2 min
  ReopenTransport reopen;
  if (kind != "file") {  // a recording ends for good; a live source may come back
    reopen = [kind, arg](std::string* err) -> std::unique_ptr<ReportTransport> {
      if (kind == "hid") {
        unsigned vid = 0, pid = 0;
        std::sscanf(arg.c_str(), "%x:%x", &vid, &pid);
        return openHidTransport(static_cast<uint16_t>(vid), static_cast<uint16_t>(pid), err);
      }
      if (kind == "hidraw") return openHidPathTransport(arg, err);
      if (kind == "fifo") return openFifoTransport(arg, err);
      return openSocketTransport(arg, err);
    };
  }
  return std::make_unique<ImuPoseSource>(std::move(t), domain.value_or(fallback), FusionParams{}, history,
                                         std::move(reopen), std::move(log));
}

}  // namespace steadyxr::imu
