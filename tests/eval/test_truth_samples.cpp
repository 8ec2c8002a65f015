// The ground truth's sample pattern (truth_samples.h), checked against what a box-filtered truth needs:
// one sample in each N x N stratum (2-D content), and an axis-aligned edge at any sub-pixel position
// covered to within half of 1/N^2 of the pixel (the edges of pictures, lines and text). A regular
// N x N grid passes the first and misses the second by up to 1/(2N).
#include "truth_samples.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <utility>

namespace steadyxr::eval {
namespace {

TEST(TruthSamples, OneSampleInEachStratumOfTheGrid) {
  for (int n : {1, 2, 4, 8, 16}) {
    std::set<std::pair<int, int>> strata;
    for (int sy = 0; sy < n; ++sy) {
      for (int sx = 0; sx < n; ++sx) {
        const glm::vec2 o = truthSampleOffset(sx, sy, n);
        ASSERT_GE(o.x, -0.5f);
        ASSERT_LT(o.x, 0.5f);
        ASSERT_GE(o.y, -0.5f);
        ASSERT_LT(o.y, 0.5f);
        strata.insert({int(std::floor((o.x + 0.5f) * n)), int(std::floor((o.y + 0.5f) * n))});
      }
    }
    EXPECT_EQ(strata.size(), size_t(n * n)) << "grid " << n;
  }
}

// The share of the samples left of (and above) an edge at position e across the pixel, against e:
// what the truth shows of a pixel that an axis-aligned edge cuts at e.
TEST(TruthSamples, AnAxisAlignedEdgeIsCoveredToHalfOfOneOverNSquared) {
  for (int n : {2, 4, 8, 16}) {
    const double cells = double(n) * n;
    double worstX = 0, worstY = 0;
    for (int k = 0; k <= 1000; ++k) {
      const double edge = k / 1000.0;
      int leftOf = 0, above = 0;
      for (int sy = 0; sy < n; ++sy) {
        for (int sx = 0; sx < n; ++sx) {
          const glm::vec2 o = truthSampleOffset(sx, sy, n);
          leftOf += o.x + 0.5 < edge ? 1 : 0;
          above += o.y + 0.5 < edge ? 1 : 0;
        }
      }
      worstX = std::max(worstX, std::fabs(leftOf / cells - edge));
      worstY = std::max(worstY, std::fabs(above / cells - edge));
    }
    EXPECT_LE(worstX, 0.5 / cells + 1e-9) << "grid " << n;
    EXPECT_LE(worstY, 0.5 / cells + 1e-9) << "grid " << n;
  }
}

}  // namespace
}  // namespace steadyxr::eval
