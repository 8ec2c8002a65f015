#include "steadyxr/imu/emulator.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>

#include <fcntl.h>
#include <linux/uhid.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <glm/gtc/quaternion.hpp>

#include "rng.h"

namespace steadyxr::imu {
namespace {

constexpr double kGravity = 9.80665;

void setError(std::string* error, const std::string& msg) {
  if (error) *error = msg;
}
std::string errnoText(const std::string& what) {
  return what + ": " + std::strerror(errno);
}

bool writeAll(int fd, std::span<const uint8_t> bytes) {
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += static_cast<size_t>(n);
  }
  return true;
}

class FdSink final : public ReportSink {
 public:
  FdSink(int fd, std::string what) : fd_(fd), what_(std::move(what)) {}
  ~FdSink() override { ::close(fd_); }
  bool write(std::span<const uint8_t> report) override { return writeAll(fd_, hid::frame(report)); }
  bool writeRaw(std::span<const uint8_t> bytes) override { return writeAll(fd_, bytes); }
  std::string describe() const override { return what_; }

 private:
  int fd_;
  std::string what_;
};

class SocketSink final : public ReportSink {
 public:
  SocketSink(int listenFd, std::string path) : listenFd_(listenFd), path_(std::move(path)) {}
  ~SocketSink() override {
    if (clientFd_ >= 0) ::close(clientFd_);
    ::close(listenFd_);
    ::unlink(path_.c_str());
  }
  bool write(std::span<const uint8_t> report) override {
    if (clientFd_ < 0) clientFd_ = ::accept4(listenFd_, nullptr, nullptr, SOCK_CLOEXEC);
    if (clientFd_ < 0) return false;
    return ::send(clientFd_, report.data(), report.size(), MSG_NOSIGNAL) ==
           static_cast<ssize_t>(report.size());
  }
  std::string describe() const override { return "socket:" + path_; }

 private:
  int listenFd_;
  int clientFd_ = -1;
  std::string path_;
};

class UhidSink final : public ReportSink {
 public:
  UhidSink(int fd, std::string name) : fd_(fd), name_(std::move(name)) {}
  ~UhidSink() override {
    uhid_event ev{};
    ev.type = UHID_DESTROY;
    [[maybe_unused]] const bool ok = writeAll(fd_, {reinterpret_cast<const uint8_t*>(&ev), sizeof ev});
    ::close(fd_);
  }
  bool write(std::span<const uint8_t> report) override {
    drainEvents();
    uhid_event ev{};
    ev.type = UHID_INPUT2;
    ev.u.input2.size = static_cast<uint16_t>(std::min<size_t>(report.size(), UHID_DATA_MAX));
    std::memcpy(ev.u.input2.data, report.data(), ev.u.input2.size);
    return writeAll(fd_, {reinterpret_cast<const uint8_t*>(&ev), sizeof ev});
  }
  std::string describe() const override { return "uhid:" + name_; }

 private:
  void drainEvents() {  // START/OPEN/CLOSE and GET_REPORT requests: read so the queue never fills
    pollfd p{fd_, POLLIN, 0};
    while (::poll(&p, 1, 0) > 0) {
      uhid_event ev{};
      if (::read(fd_, &ev, sizeof ev) <= 0) break;
      if (ev.type == UHID_GET_REPORT) {  // no feature reports: answer with an error, never hang
        uhid_event reply{};
        reply.type = UHID_GET_REPORT_REPLY;
        reply.u.get_report_reply.id = ev.u.get_report.id;
        reply.u.get_report_reply.err = EIO;
        if (!writeAll(fd_, {reinterpret_cast<const uint8_t*>(&reply), sizeof reply})) break;
      }
    }
  }
  int fd_;
  std::string name_;
};

}  // namespace

struct SensorErrors::Rng : detail::Rng {
  using detail::Rng::Rng;
};

SensorErrors::SensorErrors(const SensorModel& m, double sampleRateHz, uint64_t seed)
    : rng_(std::make_unique<Rng>(seed ^ 0x5E4502ull)) {
  constexpr double kDegToRad = 3.14159265358979323846 / 180.0;
  const double rate = std::max(sampleRateHz, 1.0);
  gyroSigma_ = m.gyroNoiseDensityDegPerSecRtHz * kDegToRad * std::sqrt(rate);
  accelSigma_ = m.accelNoiseDensityUgRtHz * 1e-6 * kGravity * std::sqrt(rate);
  biasStep_ = m.gyroBiasRandomWalkDegPerSecRtSec * kDegToRad / std::sqrt(rate);
  for (int k = 0; k < 3; ++k) {
    gyroBias_[k] = m.gyroBiasSigmaDegPerSec * kDegToRad * rng_->gaussian();
    accelBias_[k] = m.accelBiasSigmaMg * 1e-3 * kGravity * rng_->gaussian();
  }
}

SensorErrors::~SensorErrors() = default;

void SensorErrors::apply(glm::dvec3* gyro, glm::dvec3* accel) {
  for (int k = 0; k < 3; ++k) {
    (*gyro)[k] += gyroBias_[k] + gyroSigma_ * rng_->gaussian();
    (*accel)[k] += accelBias_[k] + accelSigma_ * rng_->gaussian();
    gyroBias_[k] += biasStep_ * rng_->gaussian();
  }
}

struct ReportGenerator::Noise {
  explicit Noise(uint64_t seed) : rng(seed) {}
  detail::Rng rng;
};

ReportGenerator::ReportGenerator(const MotionStream& stream, const EmulatorParams& p)
    : stream_(stream),
      p_(p),
      intervalUs_(
          static_cast<uint16_t>(std::clamp(std::lround(1e6 / std::max(p.sampleRateHz, 20.0)), 1l, 50000l))),
      noise_(std::make_unique<Noise>(p.seed ^ 0x5E5Eull)) {
  if (p.sensor.enabled) sensor_ = std::make_unique<SensorErrors>(p.sensor, 1e6 / intervalUs_, p.seed);
}

ReportGenerator::~ReportGenerator() = default;

double ReportGenerator::timeOfNextSampleSec() const {
  return static_cast<double>(sampleIndex_) * intervalUs_ * 1e-6;
}

hid::Report ReportGenerator::next() {
  hid::RawReport r;
  r.counter = static_cast<uint16_t>(p_.counterStart + sampleIndex_);
  r.intervalUs = intervalUs_;
  r.timestampUs = static_cast<uint32_t>(p_.timestampStartUs + sampleIndex_ * intervalUs_);
  for (size_t s = 0; s < hid::kSamplesPerReport; ++s, ++sampleIndex_) {
    const double t = static_cast<double>(sampleIndex_) * intervalUs_ * 1e-6;
    const MotionState m = stream_.at(t);
    const glm::dquat q(m.orientation);
    glm::dvec3 specificForce =
        glm::conjugate(q) * (glm::dvec3(m.linearAccelerationMps2) + glm::dvec3(0.0, kGravity, 0.0));
    glm::dvec3 gyro(m.angularVelocityRadPerSec);
    if (sensor_) sensor_->apply(&gyro, &specificForce);
    for (int k = 0; k < 3; ++k) {
      bool sat = false;
      const double g = gyro[k] + p_.gyroBiasRadPerSec[k] +
                       (p_.gyroNoiseRadPerSec > 0 ? p_.gyroNoiseRadPerSec * noise_->rng.gaussian() : 0.0);
      r.samples[s][k] = hid::quantize(g, hid::kGyroLsb, &sat);
      saturated_ += sat;
      const double a =
          specificForce[k] + (p_.accelNoiseMps2 > 0 ? p_.accelNoiseMps2 * noise_->rng.gaussian() : 0.0);
      r.samples[s][3 + k] = hid::quantize(a, hid::kAccelLsb, &sat);
      saturated_ += sat;
    }
  }
  return hid::encode(r);
}

std::unique_ptr<ReportSink> openReportSink(const std::string& spec, std::string* error) {
  const auto colon = spec.find(':');
  const std::string kind = spec.substr(0, colon);
  const std::string arg = colon == std::string::npos ? std::string() : spec.substr(colon + 1);
  if (kind == "file" && !arg.empty()) {
    const int fd = ::open(arg.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) return setError(error, errnoText("open " + arg)), nullptr;
    return std::make_unique<FdSink>(fd, spec);
  }
  if (kind == "fifo" && !arg.empty()) {
    struct stat st {};
    if (::stat(arg.c_str(), &st) != 0 && ::mkfifo(arg.c_str(), 0600) != 0)
      return setError(error, errnoText("mkfifo " + arg)), nullptr;
    const int fd = ::open(arg.c_str(), O_WRONLY | O_CLOEXEC);  // blocks until a reader opens
    if (fd < 0) return setError(error, errnoText("open " + arg)), nullptr;
    return std::make_unique<FdSink>(fd, spec);
  }
  if (kind == "socket" && !arg.empty()) {
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    if (arg.size() >= sizeof addr.sun_path) return setError(error, "socket path too long"), nullptr;
    std::memcpy(addr.sun_path, arg.c_str(), arg.size() + 1);
    const int fd = ::socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0);
    if (fd < 0) return setError(error, errnoText("socket")), nullptr;
    ::unlink(arg.c_str());
    if (::bind(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0 || ::listen(fd, 1) != 0) {
      setError(error, errnoText("bind/listen " + arg));
      ::close(fd);
      return nullptr;
    }
    return std::make_unique<SocketSink>(fd, arg);
  }
  if (kind == "uhid") {
    const std::string name = arg.empty() ? "steadyxr emulated head IMU" : arg;
    const int fd = ::open("/dev/uhid", O_RDWR | O_CLOEXEC);
    if (fd < 0)
      return setError(error, errnoText("/dev/uhid not available (use file:, fifo: or socket:)")), nullptr;
    uhid_event ev{};
    ev.type = UHID_CREATE2;
    std::snprintf(reinterpret_cast<char*>(ev.u.create2.name), sizeof ev.u.create2.name, "%s", name.c_str());
    const auto rd = hid::reportDescriptor();
    std::memcpy(ev.u.create2.rd_data, rd.data(), rd.size());
    ev.u.create2.rd_size = static_cast<uint16_t>(rd.size());
    ev.u.create2.bus = 0x03;  // BUS_USB
    ev.u.create2.vendor = hid::kVendorId;
    ev.u.create2.product = hid::kProductId;
    ev.u.create2.version = 1;
    if (!writeAll(fd, {reinterpret_cast<const uint8_t*>(&ev), sizeof ev})) {
      setError(error, errnoText("UHID_CREATE2"));
      ::close(fd);
      return nullptr;
    }
    return std::make_unique<UhidSink>(fd, name);
  }
  setError(error, "output '" + spec + "': expected file:PATH, fifo:PATH, socket:PATH or uhid[:NAME]");
  return nullptr;
}

}  // namespace steadyxr::imu
