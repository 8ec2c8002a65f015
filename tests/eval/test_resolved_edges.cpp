// The resolved edges of an MSAA app (eval/resolved_edges.h) on constructed images: the edge set is
// exactly the pixels where the two renders differ by a code or more, the ring their 4-neighbours and
// nothing diagonal, the rest everything else; the csv row pools both eyes.
#include "resolved_edges.h"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

namespace steadyxr::eval {
namespace {

constexpr int kSize = 8;

void setPixel(Image& im, int x, int y, float v) {
  for (int c = 0; c < 3; ++c) im.at(x, y)[c] = v;
}

std::array<Image, 2> flatPair(float v) {
  return {Image(kSize, kSize, v), Image(kSize, kSize, v)};
}

TEST(ResolvedEdges, EdgeRingAndRestFromTheDefinition) {
  auto oneSample = flatPair(0.5f);
  auto resolved = flatPair(0.5f);
  // Left eye: one pixel resolved a code brighter, and one channel of another a code darker; a difference
  // of a third of a code (not a code: no 8-bit render makes it) is not an edge.
  setPixel(resolved[0], 3, 3, 0.5f + 1.0f / 255.0f);
  resolved[0].at(6, 1)[2] = 0.5f - 1.0f / 255.0f;
  setPixel(resolved[0], 1, 6, 0.5f + 0.3f / 255.0f);
  const ResolvedEdgeMasks m = resolvedEdgeMasks(oneSample, resolved);
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize; ++x) {
      const size_t i = size_t(y) * kSize + x;
      const bool edge = (x == 3 && y == 3) || (x == 6 && y == 1);
      const bool ring =
          !edge && ((std::abs(x - 3) + std::abs(y - 3) == 1) || (std::abs(x - 6) + std::abs(y - 1) == 1));
      EXPECT_EQ(m.edge[0][i], edge) << x << "," << y;
      EXPECT_EQ(m.ring[0][i], ring) << x << "," << y;
      EXPECT_EQ(m.rest[0][i], !edge && !ring) << x << "," << y;
      // The right eye's renders are equal: all of it is the rest.
      EXPECT_EQ(m.edge[1][i] + m.ring[1][i], 0);
      EXPECT_EQ(m.rest[1][i], 1);
    }
  }
}

TEST(ResolvedEdges, ImageBorderAndSizeMismatch) {
  auto oneSample = flatPair(0.2f);
  auto resolved = flatPair(0.2f);
  setPixel(resolved[1], 0, 0, 0.9f);            // a corner: two ring pixels inside the image
  resolved[0] = Image(kSize - 1, kSize, 0.2f);  // no pair for the left eye: every pixel is the rest
  const ResolvedEdgeMasks m = resolvedEdgeMasks(oneSample, resolved);
  int edges = 0, rings = 0;
  for (size_t i = 0; i < m.edge[1].size(); ++i) edges += m.edge[1][i], rings += m.ring[1][i];
  EXPECT_EQ(edges, 1);
  EXPECT_EQ(rings, 2);
  EXPECT_EQ(m.ring[1][1], 1);
  EXPECT_EQ(m.ring[1][kSize], 1);
  for (size_t i = 0; i < m.rest[0].size(); ++i) EXPECT_EQ(m.rest[0][i], 1);
}

TEST(ResolvedEdges, CsvRowPoolsBothEyes) {
  auto oneSample = flatPair(0.0f);
  auto resolved = flatPair(0.0f);
  setPixel(resolved[0], 4, 4, 0.5f);
  setPixel(resolved[1], 2, 5, 0.5f);
  const ResolvedEdgeMasks m = resolvedEdgeMasks(oneSample, resolved);
  // Output: off by 0.1 on both edge pixels, 0.2 on one ring pixel of the right eye, exact elsewhere.
  std::array<Image, 2> truth = flatPair(0.0f), out = flatPair(0.0f);
  setPixel(out[0], 4, 4, 0.1f);
  setPixel(out[1], 2, 5, 0.1f);
  setPixel(out[1], 2, 4, 0.2f);
  std::stringstream row(resolvedEdgesCsvRow(out, truth, m));
  std::vector<double> v;
  for (std::string cell; std::getline(row, cell, ',');) v.push_back(std::stod(cell));
  ASSERT_EQ(v.size(), 6u);
  EXPECT_NEAR(v[0], 0.1, 1e-6);  // the edges: 2 pixels, both 0.1 off
  EXPECT_EQ(v[1], 2);
  EXPECT_NEAR(v[2], std::sqrt(0.04 / 8.0), 1e-6);  // the ring: 8 pixels, one 0.2 off
  EXPECT_EQ(v[3], 8);
  EXPECT_EQ(v[4], 0.0);
  EXPECT_EQ(v[5], 2 * kSize * kSize - 10);
}

}  // namespace
}  // namespace steadyxr::eval
