// libFuzzer target (clang): arbitrary bytes as a sequence of reports and as a framed stream,
// through the parser and the fusion. Traps on a NaN or a non-increasing output time.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "steadyxr/imu/fusion.h"
#include "steadyxr/imu/hid_report.h"

namespace {

void check(const steadyxr::imu::FusedSample& s, int64_t* last) {
  const auto& q = s.orientation;
  if (!std::isfinite(q.w + q.x + q.y + q.z + s.headSpeedDegPerSec) || s.timeNs <= *last) __builtin_trap();
  *last = s.timeNs;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace steadyxr::imu;
  hid::ReportParser parser;
  Fusion fusion;
  std::vector<hid::ImuSample> samples;
  int64_t last = INT64_MIN;
  auto feed = [&](std::span<const uint8_t> report) {
    samples.clear();
    parser.parse(report, &samples);
    for (const auto& s : samples)
      if (fusion.update(s)) check(fusion.state(), &last);
  };
  // 1) length-prefixed chunks, as hidraw would deliver reports
  for (size_t i = 0; i < size;) {
    const size_t len = std::min<size_t>(data[i], size - i - 1);
    feed({data + i + 1, len});
    i += 1 + len;
  }
  // 2) the same bytes as a FIFO/file stream
  hid::FrameDecoder decoder;
  decoder.feed({data, size});
  std::vector<uint8_t> report;
  while (decoder.next(&report)) feed(report);
  return 0;
}
