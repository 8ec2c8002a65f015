// HistoryContinuity (layer/xr/src/history_continuity.h): when the layer starts a frame without its
// history. The rules are from the layer's situation, not the filter: a frame without the app's
// world shown in between, time going back, or a gap longer than the eval's dropped-frame
// measurements cover (four app periods, steadyxr-eval --drop-frames).
#include "history_continuity.h"

#include <gtest/gtest.h>

namespace steadyxr::layer {
namespace {

constexpr int64_t kPeriodNs = 11'111'111;  // 90 Hz
constexpr int64_t kStartNs = 5'000'000'000;
constexpr uint64_t kSpace = 0x51, kOtherSpace = 0x52;  // two reference spaces (XrSpace handles)

// Filters `frames` frames one period apart from `t`; returns the next free display time.
int64_t filterSteadily(HistoryContinuity& c, int64_t t, int frames) {
  for (int i = 0; i < frames; ++i, t += kPeriodNs) {
    EXPECT_FALSE(c.mustDrop(t, kSpace)) << i;
    c.filtered(t, kSpace);
  }
  return t;
}

TEST(HistoryContinuity, KeepsTheHistoryAcrossUpToThreeMissedPeriods) {
  HistoryContinuity c;
  EXPECT_FALSE(c.mustDrop(kStartNs, kSpace));  // nothing filtered yet: nothing to drop
  int64_t t = filterSteadily(c, kStartNs, 10) - kPeriodNs;
  EXPECT_EQ(c.recentPeriod(), kPeriodNs);
  // Missed frames make steps of 2, 3 and 4 periods, each more than once in a row: the period
  // stays the shortest recent step, and every one of them keeps the history.
  for (int missed : {1, 2, 3, 3, 3, 3, 3, 3, 3, 3, 2, 1}) {
    t += (missed + 1) * kPeriodNs;
    EXPECT_FALSE(c.mustDrop(t, kSpace)) << missed;
    c.filtered(t, kSpace);
  }
  EXPECT_EQ(c.recentPeriod(), 2 * kPeriodNs);  // the last 8 steps: no step of one period among them
  t += 4 * kPeriodNs;
  EXPECT_FALSE(c.mustDrop(t, kSpace));  // 2 of the new period: kept
}

TEST(HistoryContinuity, DropsTheHistoryAfterALongerGap) {
  HistoryContinuity c;
  const int64_t t = filterSteadily(c, kStartNs, 10) - kPeriodNs;
  EXPECT_FALSE(c.mustDrop(t + 4 * kPeriodNs, kSpace));
  EXPECT_TRUE(c.mustDrop(t + 5 * kPeriodNs, kSpace));   // four periods missed in a row
  EXPECT_TRUE(c.mustDrop(t + 2'000'000'000, kSpace));   // a session that paused for 2 s
  EXPECT_TRUE(c.mustDrop(t, kSpace));                   // the same display time again
  EXPECT_TRUE(c.mustDrop(t - kPeriodNs, kSpace));       // time went back: a new session
  c.filtered(t + 5 * kPeriodNs, kSpace);                // the frame after the gap starts afresh
  EXPECT_FALSE(c.mustDrop(t + 6 * kPeriodNs, kSpace));  // and its successor keeps it
}

TEST(HistoryContinuity, DropsTheHistoryOnceAfterAFrameWithoutTheAppsWorld) {
  HistoryContinuity c;
  c.frameWithoutWorld();  // an app's empty frames before it renders: no history yet
  int64_t t = filterSteadily(c, kStartNs, 4);
  c.frameWithoutWorld();  // a loading screen between two levels, one period long
  EXPECT_TRUE(c.mustDrop(t + kPeriodNs, kSpace));
  c.filtered(t + kPeriodNs, kSpace);
  EXPECT_FALSE(c.mustDrop(t + 2 * kPeriodNs, kSpace));
}

TEST(HistoryContinuity, DropsTheHistoryWhenThePosesComeInAnotherSpace) {
  HistoryContinuity c;
  const int64_t t = filterSteadily(c, kStartNs, 4);
  EXPECT_TRUE(c.mustDrop(t, kOtherSpace));  // an app that moved from LOCAL to STAGE
  c.filtered(t, kOtherSpace);
  EXPECT_FALSE(c.mustDrop(t + kPeriodNs, kOtherSpace));
}

}  // namespace
}  // namespace steadyxr::layer
