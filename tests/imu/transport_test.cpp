// The reader on its real transports: file, FIFO, Unix socket, hidapi, /dev/uhid, and the
// emulator program end to end.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <thread>

#include <hidapi.h>
#include <unistd.h>

#include "imu_test_util.h"
#include "steadyxr/imu/imu_pose_source.h"
#include "steadyxr/imu/motion_extra.h"

using namespace steadyxr::imu;
using namespace std::chrono_literals;
using steadyxr::imu::test::angleDeg;

namespace {

std::string tempPath(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          ("steadyxr_imu_" + std::to_string(::getpid()) + "_" + name))
      .string();
}

}  // namespace

TEST(ImuPoseSource, FileTransportReplaysInDeviceTime) {
  std::string error;
  const auto m = makePreset("sequence", 2, &error);
  const std::string path = tempPath("reports.bin");
  {
    auto sink = openReportSink("file:" + path, &error);
    ASSERT_TRUE(sink) << error;
    EmulatorParams p;
    p.sensor.enabled = false;  // the transport's fidelity, not the sensor's errors, is tested here
    p.timestampStartUs = 0xFFFFFFFFu - 3'000'000;  // wraps 3 s in
    ReportGenerator gen(*m, p);
    const uint8_t junk[] = {0x01, 0xA5, 0x00, 0x77};
    for (int i = 0; gen.timeOfNextSampleSec() <= m->durationSec(); ++i) {
      ASSERT_TRUE(sink->write(gen.next()));
      if (i == 1000) sink->writeRaw(junk);
    }
  }
  const auto src = openImuPoseSource("file:" + path, &error);
  ASSERT_TRUE(src) << error;
  EXPECT_EQ(src->timeDomain(), TimeDomain::kDevice);
  src->waitForSamples(8600, 10s);
  for (int i = 0; i < 500 && src->stats().running; ++i) std::this_thread::sleep_for(5ms);
  const ImuStats st = src->stats();
  EXPECT_FALSE(st.running);
  EXPECT_TRUE(st.lastError.empty()) << st.lastError;
  EXPECT_EQ(st.parser.timestampWraps, 1u);
  EXPECT_EQ(st.parser.garbageBytes, 4u);                       // the junk bytes
  const int64_t t0 = int64_t(0xFFFFFFFFu - 3'000'000) * 1000;  // device time of the first sample
  double maxErr = 0;
  // After the tilt estimate has settled (its first 2 s fixation plus the second after it).
  for (double t = 3.0; t < m->durationSec() - 0.01; t += 0.0173) {
    const auto s = src->stateAt(t0 + static_cast<int64_t>(t * 1e9));
    ASSERT_TRUE(s) << t;
    maxErr = std::max(maxErr, angleDeg(glm::dquat(s->orientation), glm::dquat(m->at(t).orientation)));
  }
  std::printf("file replay of the sequence preset, sampled between samples: max error %.4f deg\n", maxErr);
  EXPECT_LT(maxErr, 0.15);
  std::filesystem::remove(path);
}

TEST(ImuPoseSource, FifoAndSocketTransportsInHostTime) {
  for (const std::string kind : {"fifo", "socket"}) {
    std::string error;
    const std::string path = tempPath(kind);
    std::filesystem::remove(path);
    std::unique_ptr<ReportSink> sink;
    std::unique_ptr<ImuPoseSource> src;
    if (kind == "socket") {  // the emulator listens, the reader connects
      sink = openReportSink("socket:" + path, &error);
      ASSERT_TRUE(sink) << error;
      src = openImuPoseSource("socket:" + path, &error);
    } else {  // the reader opens the FIFO first, so the emulator's open does not block
      src = openImuPoseSource("fifo:" + path, &error);
      ASSERT_TRUE(src) << error;
      sink = openReportSink("fifo:" + path, &error);
    }
    ASSERT_TRUE(src && sink) << kind << ": " << error;
    EXPECT_EQ(src->timeDomain(), TimeDomain::kHostMonotonic);
    const auto m = makePursuit({}, 1);
    ReportGenerator gen(*m, {});
    const int64_t start = monotonicNowNs();
    // 0.3 s of reports paced in real time, as the emulator program sends them.
    for (int i = 0; i < 75; ++i) {
      ASSERT_TRUE(sink->write(gen.next()));
      std::this_thread::sleep_until(std::chrono::steady_clock::now() + 4ms);
    }
    ASSERT_TRUE(src->waitForSamples(300, 5s)) << kind;
    const int64_t now = monotonicNowNs();
    const auto newest = src->history().newestTimeNs();
    ASSERT_TRUE(newest);
    EXPECT_GT(*newest, start);  // host CLOCK_MONOTONIC domain
    EXPECT_LE(*newest, now);
    // Predicted 10 ms past the newest sample (not past "now": on a loaded machine the paced
    // writes lag, and the newest mapped sample can be more than the 100 ms horizon before now).
    const auto s = src->stateAt(*newest + 10'000'000);
    ASSERT_TRUE(s);
    EXPECT_TRUE(s->predicted);
    EXPECT_TRUE(std::isfinite(s->headSpeedDegPerSec));
    const ImuStats st = src->stats();
    EXPECT_EQ(st.parser.reports, 75u);
    EXPECT_EQ(st.parser.droppedReports, 0u);
    std::filesystem::remove(path);
  }
}

TEST(ImuPoseSource, SpecErrorsAreReportedNotThrown) {
  std::string error;
  for (const char* bad : {"", "hid:", "hid:zz:1", "hid:12345:1", "bluetooth:x", "file:", "file:/x?clock=moon",
                          "socket:/nonexistent/steadyxr.sock", "file:/nonexistent/file"}) {
    error.clear();
    EXPECT_FALSE(openImuPoseSource(bad, &error)) << bad;
    EXPECT_FALSE(error.empty()) << bad;
  }
}

TEST(ReportSink, BadSpecsAndAMissingUhidAreErrors) {
  std::string error;
  for (const char* bad : {"", "file:", "tcp:1234", "file:/nonexistent/dir/x.bin"}) {
    error.clear();
    EXPECT_FALSE(openReportSink(bad, &error)) << bad;
    EXPECT_FALSE(error.empty()) << bad;
  }
  if (access("/dev/uhid", F_OK) != 0) {
    EXPECT_FALSE(openReportSink("uhid", &error));
    EXPECT_NE(error.find("/dev/uhid"), std::string::npos) << error;
  }
}

TEST(ImuPoseSource, HidapiOpensByVidPidOrFailsCleanly) {
  // Real hidapi: enumerate and open. On a machine without the device this must fail with a
  // clear error and no crash; where an emulated (uhid) device exists, it opens.
  ASSERT_EQ(hid_init(), 0);
  hid_device_info* list = hid_enumerate(hid::kVendorId, hid::kProductId);
  const bool present = list != nullptr;
  hid_free_enumeration(list);
  std::string error;
  const auto src = openImuPoseSource("hid:1209:0001", &error);
  if (present) {
    EXPECT_TRUE(src) << error;
  } else {
    EXPECT_FALSE(src);
    EXPECT_NE(error.find("1209:0001"), std::string::npos) << error;
  }
  EXPECT_FALSE(openImuPoseSource("hidraw:/dev/hidraw-does-not-exist", &error));
}

TEST(ImuPoseSource, UhidVirtualDeviceThroughHidapi) {
  if (access("/dev/uhid", R_OK | W_OK) != 0)
    GTEST_SKIP()
        << "/dev/uhid is not available on this machine (no uhid module or no permission): the "
           "virtual HID device path cannot run here; the FIFO/socket/file transports carry the same bytes";
  std::string error;
  auto sink = openReportSink("uhid:steadyxr test IMU", &error);
  ASSERT_TRUE(sink) << error;
  std::unique_ptr<ImuPoseSource> src;
  for (int i = 0; i < 100 && !src; ++i) {  // udev needs a moment to create the hidraw node
    src = openImuPoseSource("hid:1209:0001", &error);
    if (!src) std::this_thread::sleep_for(20ms);
  }
  ASSERT_TRUE(src) << error;
  const auto m = makeFastTurn({}, 1);
  ReportGenerator gen(*m, {});
  for (int i = 0; i < 150; ++i) {
    ASSERT_TRUE(sink->write(gen.next()));
    std::this_thread::sleep_for(4ms);
  }
  EXPECT_TRUE(src->waitForSamples(400, 5s));
  EXPECT_GT(src->stats().parser.reports, 100u);
}

#ifdef STEADYXR_IMU_EMU
TEST(Emulator, ProgramWritesReportsAndAReplayableGroundTruth) {
  const std::string bin = tempPath("emu.bin"), truth = tempPath("truth.csv");
  const std::string cmd = std::string(STEADYXR_IMU_EMU) +
                          " --motion fixation --seed 5 --duration 6 --no-sensor-noise --out file:" + bin +
                          " --truth " + truth + " --ts-start 4294000000 2>/dev/null";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  std::string error;
  const auto gt = loadTrace(truth, &error);
  ASSERT_TRUE(gt) << error;
  EXPECT_NEAR(gt->durationSec(), 6.0, 1e-6);
  const auto src = openImuPoseSource("file:" + bin, &error);
  ASSERT_TRUE(src) << error;
  src->waitForSamples(6000, 10s);
  const int64_t t0 = int64_t(4294000000u) * 1000;
  double maxErr = 0;
  for (double t = 5.0; t <= 5.99; t += 0.01) {  // after the tilt has settled
    const auto s = src->stateAt(t0 + static_cast<int64_t>(t * 1e9));
    ASSERT_TRUE(s) << t;
    maxErr = std::max(maxErr, angleDeg(glm::dquat(s->orientation), glm::dquat(gt->at(t).orientation)));
  }
  std::printf("emulator program -> file -> reader vs its ground-truth CSV: max error %.4f deg\n", maxErr);
  EXPECT_LT(maxErr, 0.05);
  EXPECT_EQ(src->stats().parser.timestampWraps, 1u);
  // Replaying the ground truth: as long as the trace is fine; longer is an error, not a held pose.
  const std::string replay =
      std::string(STEADYXR_IMU_EMU) + " --motion trace:" + truth + " --out file:/dev/null";
  EXPECT_EQ(std::system((replay + " --duration 6 2>/dev/null").c_str()), 0);
  EXPECT_NE(std::system((replay + " --duration 6.01 2>/dev/null").c_str()), 0);
  // Bad arguments: usage and a non-zero exit.
  EXPECT_NE(
      std::system(
          (std::string(STEADYXR_IMU_EMU) + " --motion wobble --out file:/dev/null 2>/dev/null").c_str()),
      0);
  std::filesystem::remove(bin);
  std::filesystem::remove(truth);
}

TEST(Emulator, ProgramServesASocketInRealTime) {
  // A separate emulator process pacing reports in real time; the reader maps them to host time.
  const std::string sock = tempPath("emu.sock");
  std::filesystem::remove(sock);
  const std::string cmd = std::string(STEADYXR_IMU_EMU) +
                          " --motion pursuit --duration 0.6 --out socket:" + sock + " 2>/dev/null &";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  std::string error;
  std::unique_ptr<ImuPoseSource> src;
  for (int i = 0; i < 200 && !src; ++i) {  // until the emulator listens
    src = openImuPoseSource("socket:" + sock, &error);
    if (!src) std::this_thread::sleep_for(10ms);
  }
  ASSERT_TRUE(src) << error;
  const int64_t start = monotonicNowNs();
  ASSERT_TRUE(src->waitForSamples(300, 5s));
  const auto newest = src->history().newestTimeNs();
  ASSERT_TRUE(newest);
  EXPECT_NEAR(static_cast<double>(*newest), static_cast<double>(monotonicNowNs()),
              50e6);  // host clock, +-50 ms
  EXPECT_GT(*newest, start);
  // Samples keep their device spacing on the host clock: 250 ms ago lies inside the history.
  const auto first = src->stateAt(*newest - 250'000'000);
  ASSERT_TRUE(first);
  EXPECT_FALSE(first->predicted);
  // The emulator exits: the stream ends (the reader then tries to reconnect, see below).
  for (int i = 0; i < 300 && src->stats().streamEnds == 0; ++i) std::this_thread::sleep_for(10ms);
  EXPECT_EQ(src->stats().streamEnds, 1u);
  EXPECT_EQ(src->stats().parser.droppedReports, 0u);
}
#endif

// A live source whose stream ends (the emulator, or a device, goes away and comes back): the
// end is logged and the reader reconnects, within kReconnectDelays, then gives up for good.
TEST(ImuPoseSource, LiveStreamEndIsLoggedAndReconnected) {
  std::string error;
  const std::string path = tempPath("reconnect");
  std::filesystem::remove(path);
  std::mutex logMu;
  std::vector<std::string> lines;
  auto log = [&](const std::string& l) {
    std::lock_guard lock(logMu);
    lines.push_back(l);
  };
  auto count = [&](const std::string& what) {
    std::lock_guard lock(logMu);
    return std::count_if(lines.begin(), lines.end(),
                         [&](const std::string& l) { return l.find(what) != std::string::npos; });
  };
  const auto m = makePursuit({}, 1);
  ReportGenerator gen(*m, {});
  auto send = [&](ReportSink& sink, int n) {
    for (int i = 0; i < n; ++i) {
      ASSERT_TRUE(sink.write(gen.next()));
      std::this_thread::sleep_for(4ms);
    }
  };
  auto sink = openReportSink("socket:" + path, &error);
  ASSERT_TRUE(sink) << error;
  const auto src = openImuPoseSource("socket:" + path, &error, log);
  ASSERT_TRUE(src) << error;
  send(*sink, 25);
  ASSERT_TRUE(src->waitForSamples(100, 5s));
  sink.reset();  // the emulator goes away
  for (int i = 0; i < 200 && count("end of stream") == 0; ++i) std::this_thread::sleep_for(5ms);
  EXPECT_EQ(count("end of stream on socket:"), 1);
  sink = openReportSink("socket:" + path, &error);  // and comes back
  ASSERT_TRUE(sink) << error;
  for (int i = 0; i < 800 && src->stats().reconnects == 0; ++i) std::this_thread::sleep_for(5ms);
  send(*sink, 25);
  EXPECT_TRUE(src->waitForSamples(200, 5s)) << "no samples after the reconnect";
  EXPECT_EQ(src->stats().reconnects, 1u);
  EXPECT_EQ(count("imu: reconnected to socket:"), 1);
  EXPECT_TRUE(src->stats().running);

  sink.reset();  // gone for good: bounded retries, then one line and the reader stops
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < 2000 && src->stats().running; ++i) std::this_thread::sleep_for(5ms);
  const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_FALSE(src->stats().running);
  EXPECT_EQ(count("cannot reconnect"), 1);
  EXPECT_EQ(src->stats().streamEnds, 2u);
  std::printf("reconnect: gave up after %.1f s\n", waited);
  EXPECT_LT(waited, 9.0);  // 6.3 s of delays in kReconnectDelays, plus the connect attempts
  std::filesystem::remove(path);
}
