#include "frame_clock.h"

#include <cmath>

namespace steadyxr::eval {
namespace {

// splitmix64: a fixed, portable sequence for a seed (std:: distributions differ between libraries).
uint64_t nextDraw(uint64_t* state) {
  uint64_t z = (*state += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}
double unitDraw(uint64_t* state) {
  return double(nextDraw(state) >> 11) * 0x1.0p-53;
}  // [0, 1)

std::vector<int64_t> periodsOfFrames(int frames, double dropFraction, uint64_t seed) {
  std::vector<int64_t> periods;
  if (frames <= 0) return periods;
  periods.reserve(size_t(frames));
  periods.push_back(0);
  uint64_t state = seed ^ 0xD809F3A5C1E2B467ull;  // its own stream: not the motion's or the noise's
  for (int f = 1; f < frames; ++f) {
    int missed = 0;
    while (dropFraction > 0.0 && missed < kMostMissedInARow && unitDraw(&state) < dropFraction) ++missed;
    periods.push_back(periods.back() + 1 + missed);
  }
  return periods;
}

}  // namespace

FrameClock::FrameClock(int frames, double firstSec, double dt, double dropFraction, uint64_t seed)
    : firstSec_(firstSec), dt_(dt), periods_(periodsOfFrames(frames, dropFraction, seed)) {}

int FrameClock::firstFrameAtOrAfterRunTime(double sinceFirstSec) const {
  // The period at or after the time (a change a hair before a frame's time counts at that frame),
  // then the first frame shown in it or later.
  const int64_t period = int64_t(std::ceil(sinceFirstSec / dt_ - 1e-9));
  if (period < 0) return -1;  // a period or more before the run: not one of its changes
  for (int f = 0; f < frames(); ++f) {
    if (periods_[f] >= period) return f;
  }
  return -1;
}

int64_t spanInPeriods(int frames, double dropFraction, uint64_t seed) {
  const std::vector<int64_t> periods = periodsOfFrames(frames, dropFraction, seed);
  return periods.empty() ? 0 : periods.back();
}

}  // namespace steadyxr::eval
