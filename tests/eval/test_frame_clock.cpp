// The submitted frames' times under --drop-frames (eval/frame_clock.h), checked against what an app
// that misses deadlines does: each frame one or more whole app periods after the last, misses drawn
// as often as asked, and a change first seen by the first frame shown at or after it.
#include "frame_clock.h"

#include <gtest/gtest.h>

namespace steadyxr::eval {
namespace {

constexpr double kFirstSec = 2.5, kDt = 1.0 / 90.0;

TEST(EvalFrameClock, WithoutDropsEveryPeriodIsShown) {
  const FrameClock clock(48, kFirstSec, kDt, 0.0, 7);
  EXPECT_EQ(clock.missedPeriods(), 0);
  for (int f = 0; f < 48; ++f) EXPECT_EQ(clock.timeOf(f), kFirstSec + f * kDt) << f;  // the suite's old times
  EXPECT_EQ(clock.firstFrameAtOrAfter(kFirstSec + 10 * kDt), 10);
  EXPECT_EQ(clock.firstFrameAtOrAfter(kFirstSec + 10.2 * kDt), 11);
  // A change within the period before the first frame is the first frame's; one earlier is before the run.
  EXPECT_EQ(clock.firstFrameAtOrAfter(kFirstSec - 0.5 * kDt), 0);
  EXPECT_EQ(clock.firstFrameAtOrAfter(kFirstSec - 1.5 * kDt), -1);
  EXPECT_EQ(clock.firstFrameAtOrAfter(kFirstSec + 47.5 * kDt), -1);  // after its last frame
  EXPECT_EQ(clock.firstFrameAtOrAfterRunTime(3 * kDt), 3);
  EXPECT_EQ(spanInPeriods(48, 0.0, 7), 47);
}

TEST(EvalFrameClock, MissesWholePeriodsAsOftenAsAsked) {
  const double p = 0.3;
  const int frames = 4000;
  const FrameClock clock(frames, kFirstSec, kDt, p, 11);
  // Each step: 1 + the periods missed, at most kMostMissedInARow; a miss after a miss with p again,
  // so the mean of the missed periods is p + p^2 + p^3.
  int64_t missed = 0;
  for (int f = 1; f < frames; ++f) {
    const int64_t step = clock.periodOf(f) - clock.periodOf(f - 1);
    ASSERT_GE(step, 1) << f;
    ASSERT_LE(step, 1 + kMostMissedInARow) << f;
    missed += step - 1;
    EXPECT_DOUBLE_EQ(clock.timeOf(f), kFirstSec + double(clock.periodOf(f)) * kDt);
  }
  EXPECT_EQ(missed, clock.missedPeriods());
  const double expected = p + p * p + p * p * p;
  EXPECT_NEAR(double(missed) / (frames - 1), expected, 0.04);  // about 4 standard errors
  EXPECT_EQ(spanInPeriods(frames, p, 11), clock.periodOf(frames - 1));
  EXPECT_EQ(missedPeriods(frames, p, 11), missed);  // the report's count, without the clock
  EXPECT_EQ(missedPeriods(0, p, 11), 0);
  // The same seed draws the same misses (every case of a run); another seed others.
  const FrameClock again(frames, kFirstSec, kDt, p, 11), other(frames, kFirstSec, kDt, p, 12);
  EXPECT_EQ(again.missedPeriods(), clock.missedPeriods());
  bool differs = false;
  for (int f = 0; f < frames; ++f) differs |= other.periodOf(f) != clock.periodOf(f);
  EXPECT_TRUE(differs);
}

TEST(EvalFrameClock, AChangeInAMissedPeriodIsSeenByTheNextFrameShown) {
  const FrameClock clock(200, kFirstSec, kDt, 0.3, 5);
  int checked = 0;
  for (int f = 1; f < clock.frames(); ++f) {
    if (clock.periodOf(f) - clock.periodOf(f - 1) < 2) continue;
    // A change during the missed period (and one a hair after the frame before) is first shown by frame f.
    const double missedPeriodSec = kFirstSec + double(clock.periodOf(f - 1) + 1) * kDt;
    EXPECT_EQ(clock.firstFrameAtOrAfter(missedPeriodSec), f) << f;
    EXPECT_EQ(clock.firstFrameAtOrAfter(clock.timeOf(f - 1) + 1e-4 * kDt), f) << f;
    EXPECT_EQ(clock.firstFrameAtOrAfter(clock.timeOf(f)), f) << f;
    ++checked;
  }
  EXPECT_GT(checked, 20);  // the premise: a run with misses
}

}  // namespace
}  // namespace steadyxr::eval
