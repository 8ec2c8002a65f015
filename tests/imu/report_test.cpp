#include <gtest/gtest.h>

#include <cstring>

#include "../../imu/src/rng.h"
#include "imu_test_util.h"
#include "steadyxr/imu/hid_report.h"

using namespace steadyxr::imu;
using namespace steadyxr::imu::hid;

namespace {

hid::Report sampleReport(uint16_t counter, uint32_t tsUs, int16_t gyroY = 100) {
  RawReport r;
  r.counter = counter;
  r.timestampUs = tsUs;
  for (auto& s : r.samples) s = {0, gyroY, 0, 0, 9807, 0};
  return encode(r);
}

// A minimal HID descriptor walker: enough to check what the kernel's parser will compute.
struct DescriptorSummary {
  int inputBitsReport1 = 0;
  int depth = 0, maxDepth = 0;
  bool balanced = true;
  std::vector<uint32_t> sensorUsages;
};

DescriptorSummary walk(const std::vector<uint8_t>& d) {
  DescriptorSummary s;
  uint32_t reportSize = 0, reportCount = 0, reportId = 0, usagePage = 0;
  for (size_t i = 0; i < d.size();) {
    const uint8_t prefix = d[i];
    const int size = (prefix & 3) == 3 ? 4 : (prefix & 3);
    uint32_t v = 0;
    for (int k = 0; k < size && i + 1 + k < d.size(); ++k) v |= uint32_t(d[i + 1 + k]) << (8 * k);
    switch (prefix & 0xFC) {
      case 0x04:
        usagePage = v;
        break;
      case 0x74:
        reportSize = v;
        break;
      case 0x94:
        reportCount = v;
        break;
      case 0x84:
        reportId = v;
        break;
      case 0x08:
        if (usagePage == 0x20) s.sensorUsages.push_back(v);
        break;
      case 0x80:
        if (reportId == 1) s.inputBitsReport1 += static_cast<int>(reportSize * reportCount);
        break;
      case 0xA0:
        s.maxDepth = std::max(s.maxDepth, ++s.depth);
        break;
      case 0xC0:
        if (--s.depth < 0) s.balanced = false;
        break;
      default:
        break;
    }
    i += 1 + size;
  }
  s.balanced = s.balanced && s.depth == 0;
  return s;
}

}  // namespace

TEST(HidReport, DescriptorDescribesTheReportExactly) {
  const auto d = reportDescriptor();
  const auto s = walk(d);
  EXPECT_TRUE(s.balanced);
  EXPECT_EQ(s.maxDepth, 2);
  EXPECT_EQ(s.inputBitsReport1, static_cast<int>((kReportBytes - 1) * 8));  // everything but the ID byte
  auto count = [&](uint32_t u) { return std::count(s.sensorUsages.begin(), s.sensorUsages.end(), u); };
  EXPECT_EQ(count(0x76), 4);    // Motion: Gyrometer 3D, one per sample
  EXPECT_EQ(count(0x73), 4);    // Motion: Accelerometer 3D
  EXPECT_EQ(count(0x0457), 4);  // Angular velocity X
  EXPECT_EQ(count(0x0455), 4);  // Acceleration Z
  EXPECT_EQ(count(0x0529), 1);  // Timestamp
  EXPECT_LT(d.size(), 4096u);   // HID_MAX_DESCRIPTOR_SIZE
}

TEST(HidReport, EncodeDecodeRoundTripAndLayout) {
  RawReport r;
  r.counter = 0xBEEF;
  r.intervalUs = 1000;
  r.timestampUs = 0x12345678;
  r.samples[3] = {-1, 2, -32767, 32767, 5, -6};
  const Report bytes = encode(r);
  EXPECT_EQ(bytes[0], kReportId);
  EXPECT_EQ(bytes[1], 0xEF);
  EXPECT_EQ(bytes[2], 0xBE);
  EXPECT_EQ(bytes[5], 0x78);
  EXPECT_EQ(bytes[8], 0x12);
  RawReport back;
  ASSERT_EQ(decode(bytes, &back), DecodeStatus::kOk);
  EXPECT_EQ(back.counter, r.counter);
  EXPECT_EQ(back.timestampUs, r.timestampUs);
  EXPECT_EQ(back.samples, r.samples);
  bool sat = false;
  EXPECT_EQ(quantize(100.0, kGyroLsb, &sat), 32767);
  EXPECT_TRUE(sat);
  EXPECT_EQ(quantize(-0.0015, kGyroLsb, &sat), -2);
  EXPECT_FALSE(sat);
  EXPECT_EQ(quantize(std::nan(""), kGyroLsb, &sat), 0);
  EXPECT_TRUE(sat);
}

TEST(ReportParser, CountsAndSkipsMalformedReports) {
  ReportParser p;
  std::vector<ImuSample> out;
  const Report good = sampleReport(0, 1000);
  EXPECT_EQ(p.parse(std::span(good).first(20), &out), 0u);
  EXPECT_EQ(p.parse(std::span<const uint8_t>(), &out), 0u);
  Report wrong = good;
  wrong[0] = 2;
  EXPECT_EQ(p.parse(wrong, &out), 0u);
  std::vector<uint8_t> longer(good.begin(), good.end());
  longer.resize(64, 0xCC);
  EXPECT_EQ(p.parse(longer, &out), kSamplesPerReport);
  EXPECT_EQ(p.parse(good, &out), 0u);  // same counter again: duplicate
  EXPECT_EQ(p.stats().tooShort, 2u);
  EXPECT_EQ(p.stats().wrongReportId, 1u);
  EXPECT_EQ(p.stats().tooLong, 1u);
  EXPECT_EQ(p.stats().duplicates, 1u);
  ASSERT_EQ(out.size(), kSamplesPerReport);
  EXPECT_NEAR(out[0].gyroRadPerSec.y, 0.1f, 1e-6);
  EXPECT_NEAR(out[0].accelMps2.y, 9.807f, 1e-4);
  EXPECT_EQ(out[1].deviceTimeNs - out[0].deviceTimeNs, 1'000'000);
}

TEST(ReportParser, RepairsCounterGapsWrapsAndClockJumps) {
  ReportParser p;
  std::vector<ImuSample> out;
  const uint32_t t0 = 0xFFFFFFFFu - 6000;  // wraps after a few reports
  uint16_t c = 65530;                      // the counter wraps too
  auto feed = [&](uint16_t counter, uint32_t ts) { return p.parse(sampleReport(counter, ts), &out); };
  for (int i = 0; i < 3; ++i) feed(c + 4 * i, t0 + 4000u * i);  // normal
  feed(c + 4 * 5, t0 + 4000u * 5);                              // two reports dropped
  feed(c + 4 * 6, t0 + 4000u * 6 - 50'000);                     // timestamp goes backwards
  feed(c + 4 * 7, t0 + 4000u * 7 + 900'000);                    // timestamp jumps 0.9 s
  feed(c + 4 * 8, t0 + 4000u * 8);                              // back to normal
  const auto& st = p.stats();
  EXPECT_EQ(st.droppedReports, 2u);
  // A one-off glitch is seen twice: going off, and coming back (a real clock step, only once).
  EXPECT_GE(st.timestampBackwards, 1u);
  EXPECT_GE(st.timestampJumps, 1u);
  EXPECT_EQ(st.timestampBackwards + st.timestampJumps, 3u);
  EXPECT_GE(st.timestampWraps, 1u);
  ASSERT_EQ(out.size(), 7 * kSamplesPerReport);
  // Output time: continuous, 1 ms per sample, counting the 8 dropped samples.
  for (size_t i = 1; i < out.size(); ++i) {
    const int64_t dt = out[i].deviceTimeNs - out[i - 1].deviceTimeNs;
    EXPECT_EQ(dt, i == 12 ? 9'000'000 : 1'000'000) << i;
  }
}

TEST(ReportParser, SaturatedAndImplausibleValues) {
  ReportParser p;
  std::vector<ImuSample> out;
  RawReport r;
  r.timestampUs = 0;
  for (auto& s : r.samples) s = {0, 0, 0, 0, 9807, 0};
  r.samples[1] = {32767, 0, 0, -32768, 9807, 0};  // gyro x saturated and a huge step; accel invalid
  p.parse(encode(r), &out);
  ASSERT_EQ(out.size(), 4u);
  EXPECT_EQ(p.stats().saturatedValues, 2u);
  EXPECT_EQ(p.stats().implausibleSamples, 1u);
  EXPECT_FLOAT_EQ(out[1].gyroRadPerSec.x, 0.0f);  // held: 32.8 rad/s after 0 in 1 ms is no head
  EXPECT_FALSE(out[1].accelValid);
  EXPECT_TRUE(out[2].accelValid);
}

TEST(FrameDecoder, ResynchronisesAfterGarbage) {
  FrameDecoder d;
  const Report r1 = sampleReport(0, 0), r2 = sampleReport(4, 4000);
  std::vector<uint8_t> bytes = {0x00, 0xA5, 0x13, 0x5A};  // garbage, including a false magic start
  for (auto b : frame(r1)) bytes.push_back(b);
  bytes.insert(bytes.end(), {0xA5, 0x5A, 0x00, 0xFF});  // zero-length frame: garbage
  for (auto b : frame(r2)) bytes.push_back(b);
  std::vector<uint8_t> rep;
  // Fed in awkward pieces, as a pipe delivers them.
  for (size_t i = 0; i < bytes.size(); i += 7)
    d.feed(std::span(bytes).subspan(i, std::min<size_t>(7, bytes.size() - i)));
  ASSERT_TRUE(d.next(&rep));
  EXPECT_TRUE(std::equal(rep.begin(), rep.end(), r1.begin(), r1.end()));
  ASSERT_TRUE(d.next(&rep));
  EXPECT_TRUE(std::equal(rep.begin(), rep.end(), r2.begin(), r2.end()));
  EXPECT_FALSE(d.next(&rep));
  EXPECT_EQ(d.garbageBytes(), 8u);
}

// >= 10^6 random and mutated reports through parser and fusion: no crash (ASan/UBSan in the
// sanitizer build), no NaN, orientation stays a unit quaternion, time never goes backwards.
TEST(ReportParserFuzz, MillionRandomAndMutatedReports) {
  std::string error;
  const auto motion = makePreset("sequence", 11, &error);
  const auto valid = test::generate(*motion, 2.0);
  steadyxr::imu::detail::Rng rng(0xF022);
  test::Pipeline pipe;
  constexpr int kReports = 1'000'000;
  std::vector<uint8_t> buf;
  size_t nextValid = 0;
  int64_t lastTime = INT64_MIN;
  uint64_t nonFinite = 0, backwards = 0;
  for (int i = 0; i < kReports; ++i) {
    const auto& base = valid[nextValid++ % valid.size()];
    buf.assign(base.begin(), base.end());
    switch (rng.next() % 6) {
      case 0:
        break;  // valid (keeps the parser's state machine in play)
      case 1:   // flip a few bits
        for (int k = 0, n = 1 + rng.next() % 4; k < n; ++k)
          buf[rng.next() % buf.size()] ^= uint8_t(1u << (rng.next() % 8));
        break;
      case 2:  // random bytes, random length, right report ID most of the time
        buf.resize(rng.next() % 80);
        for (auto& b : buf) b = static_cast<uint8_t>(rng.next());
        if (!buf.empty() && rng.next() % 4) buf[0] = kReportId;
        break;
      case 3:  // truncated or extended
        buf.resize(rng.next() % 70, static_cast<uint8_t>(rng.next()));
        break;
      case 4:  // counter / timestamp mutations
        for (int k = 1; k < 9; ++k)
          if (rng.next() % 3 == 0) buf[k] = static_cast<uint8_t>(rng.next());
        break;
      default:  // extreme values
        for (size_t k = kHeaderBytes; k + 1 < buf.size(); k += 2)
          if (rng.next() % 4 == 0) {
            const uint16_t v = rng.next() % 2 ? 0x7FFF : 0x8000;
            buf[k] = uint8_t(v);
            buf[k + 1] = uint8_t(v >> 8);
          }
        break;
    }
    const size_t before = pipe.out.size();
    pipe.feed(buf);
    for (size_t k = before; k < pipe.out.size(); ++k) {
      nonFinite += !test::finite(pipe.out[k]);
      backwards += pipe.out[k].timeNs <= lastTime;
      lastTime = pipe.out[k].timeNs;
    }
    if (pipe.out.size() > 100000) pipe.out.clear();
  }
  const auto& st = pipe.parser.stats();
  std::printf(
      "fuzz: %d reports: %llu accepted, %llu short, %llu wrong id, %llu suspect, %llu implausible samples\n",
      kReports, (unsigned long long)st.reports, (unsigned long long)st.tooShort,
      (unsigned long long)st.wrongReportId, (unsigned long long)st.suspectReports,
      (unsigned long long)st.implausibleSamples);
  EXPECT_EQ(nonFinite, 0u);
  EXPECT_EQ(backwards, 0u);
  EXPECT_GT(st.reports, 100000u);
  EXPECT_GT(st.tooShort + st.wrongReportId + st.suspectReports + st.duplicates, 100000u);
}
