// steadyxr-imu-emu: simulated head motion -> byte-exact HID IMU reports on a transport.
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "rng.h"
#include "steadyxr/imu/emulator.h"
#include "steadyxr/imu/hid_report.h"
#include "steadyxr/imu/motion.h"
#include "steadyxr/imu/motion_extra.h"

namespace {

constexpr const char* kUsage = R"(usage: steadyxr-imu-emu [options]
  --motion NAME        a preset (--list-motions) or trace:PATH                 (default fixation)
  --list-motions       print the motion presets with their parameters and exit
  --seed N             deterministic seed (default 1)
  --duration SEC       default: the motion's natural length
  --rate HZ            sample rate (default 1000)
  --out SPEC           file:PATH | fifo:PATH | socket:PATH | uhid[:NAME]      (required)
  --truth PATH         also write the simulated ground truth as a trace CSV (replayable)
  --truth-rate HZ      rate of the ground-truth rows (default: the sample rate)
  --realtime | --fast  pace reports in real time (default for fifo/socket/uhid) or not (file)
  --ts-start US        first device timestamp in microseconds (e.g. 4294000000 to test wrap)
  --no-sensor-noise    exact (quantised) values: switch the consumer-MEMS sensor model off
                       (BMI160 figures: gyro 0.007 deg/s/rtHz, bias 0.05 deg/s + random walk,
                       accel 180 ug/rtHz, bias 2 mg; on by default, seeded by --seed)
  --gyro-noise RAD_S   extra white gyro noise per sample;  --accel-noise M_S2  likewise
  --drop P             drop each report with probability P (fault injection)
  --garbage P          after each report, with probability P, write random bytes
  --print-descriptor   print the HID report descriptor as hex and exit
)";

struct Options {
  std::string motion = "fixation", out, truth;
  uint64_t seed = 1;
  double duration = -1.0, rate = 1000.0, truthRate = -1.0, drop = 0.0, garbage = 0.0;
  double gyroNoise = 0.0, accelNoise = 0.0;
  uint32_t tsStart = 0;
  int realtime = -1;  // -1: by transport
  bool printDescriptor = false, listMotions = false, sensorNoise = true;
};

bool parse(int argc, char** argv, Options* o) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> const char* { return i + 1 < argc ? argv[++i] : nullptr; };
    const char* v = nullptr;
    if (a == "--realtime")
      o->realtime = 1;
    else if (a == "--fast")
      o->realtime = 0;
    else if (a == "--print-descriptor")
      o->printDescriptor = true;
    else if (a == "--list-motions")
      o->listMotions = true;
    else if (a == "--no-sensor-noise")
      o->sensorNoise = false;
    else if (a == "-h" || a == "--help")
      return false;
    else if (!(v = value()))
      return false;
    else if (a == "--motion")
      o->motion = v;
    else if (a == "--seed")
      o->seed = std::strtoull(v, nullptr, 0);
    else if (a == "--duration")
      o->duration = std::atof(v);
    else if (a == "--rate")
      o->rate = std::atof(v);
    else if (a == "--out")
      o->out = v;
    else if (a == "--truth")
      o->truth = v;
    else if (a == "--truth-rate")
      o->truthRate = std::atof(v);
    else if (a == "--ts-start")
      o->tsStart = static_cast<uint32_t>(std::strtoull(v, nullptr, 0));
    else if (a == "--gyro-noise")
      o->gyroNoise = std::atof(v);
    else if (a == "--accel-noise")
      o->accelNoise = std::atof(v);
    else if (a == "--drop")
      o->drop = std::atof(v);
    else if (a == "--garbage")
      o->garbage = std::atof(v);
    else
      return false;
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace steadyxr::imu;
  Options o;
  if (!parse(argc, argv, &o)) {
    std::fputs(kUsage, stderr);
    return 2;
  }
  if (o.printDescriptor) {
    for (const uint8_t b : hid::reportDescriptor()) std::printf("%02x ", b);
    std::printf("\n");
    return 0;
  }
  if (o.listMotions) {
    for (const MotionPreset& p : motionPresets())
      std::printf("%-22s %-12s %s%s\n", p.name.c_str(), p.motionClass.c_str(), p.summary.c_str(),
                  p.inCorpus ? "" : "  (not in the corpus)");
    return 0;
  }
  if (o.out.empty() || o.rate <= 0.0) {
    std::fputs(kUsage, stderr);
    return 2;
  }
  std::signal(SIGPIPE, SIG_IGN);  // a reader going away is reported by write(), not a signal
  std::string error;
  const auto stream = makePreset(o.motion, o.seed, &error);
  if (!stream) {
    std::fprintf(stderr, "steadyxr-imu-emu: %s\n", error.c_str());
    return 1;
  }
  const double duration = o.duration >= 0.0 ? o.duration : stream->durationSec();
  if (duration > stream->validUntilSec() + 1e-9) {  // a trace would silently hold its last pose
    std::fprintf(stderr, "steadyxr-imu-emu: %s ends at %.3f s, shorter than the requested %.3f s\n",
                 stream->describe().c_str(), stream->validUntilSec(), duration);
    return 1;
  }
  if (!o.truth.empty() &&
      !writeTrace(*stream, o.truthRate > 0 ? o.truthRate : o.rate, duration, o.truth, &error)) {
    std::fprintf(stderr, "steadyxr-imu-emu: %s\n", error.c_str());
    return 1;
  }
  const auto sink = openReportSink(o.out, &error);
  if (!sink) {
    std::fprintf(stderr, "steadyxr-imu-emu: %s\n", error.c_str());
    return 1;
  }
  EmulatorParams ep;
  ep.sampleRateHz = o.rate;
  ep.timestampStartUs = o.tsStart;
  ep.gyroNoiseRadPerSec = o.gyroNoise;
  ep.accelNoiseMps2 = o.accelNoise;
  ep.sensor.enabled = o.sensorNoise;
  ep.seed = o.seed;
  ReportGenerator gen(*stream, ep);
  steadyxr::imu::detail::Rng faults(o.seed ^ 0xFA17ull);
  const bool realtime = o.realtime >= 0 ? o.realtime == 1 : o.out.rfind("file:", 0) != 0;
  std::fprintf(stderr, "steadyxr-imu-emu: %s -> %s, %.2f s at %.0f Hz%s\n", stream->describe().c_str(),
               sink->describe().c_str(), duration, o.rate, realtime ? " (real time)" : "");
  const auto start = std::chrono::steady_clock::now();
  uint64_t reports = 0, dropped = 0;
  while (gen.timeOfNextSampleSec() <= duration) {
    const double t = gen.timeOfNextSampleSec();
    const hid::Report r = gen.next();
    if (realtime)  // a report leaves when its last sample has been measured
      std::this_thread::sleep_until(
          start + std::chrono::duration<double>(t + (hid::kSamplesPerReport - 1) * gen.intervalUs() * 1e-6));
    if (o.drop > 0.0 && faults.uniform() < o.drop) {
      ++dropped;
      continue;
    }
    if (!sink->write(r)) {
      std::fprintf(stderr, "steadyxr-imu-emu: write to %s failed\n", sink->describe().c_str());
      return 1;
    }
    ++reports;
    if (o.garbage > 0.0 && faults.uniform() < o.garbage) {
      std::vector<uint8_t> junk(1 + faults.next() % 80);
      for (auto& b : junk) b = static_cast<uint8_t>(faults.next());
      sink->writeRaw(junk);
    }
  }
  std::fprintf(stderr, "steadyxr-imu-emu: %llu reports written, %llu dropped, %llu saturated values\n",
               static_cast<unsigned long long>(reports), static_cast<unsigned long long>(dropped),
               static_cast<unsigned long long>(gen.saturatedValues()));
  return 0;
}
