// The layer's optional jitter: what xrLocateViews injects must be recognised and undone in
// xrEndFrame (unjittered fov to the core and the runtime, the pixel offset to the core).
#include "rewrite.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <set>
#include <utility>

namespace steadyxr::layer {
namespace {

constexpr VkExtent2D kSize{320, 240};

// Pixel coordinates (x right, y down, 0 at the top-left corner) at which a direction with
// tangents (tx, ty) (x right, y up) lands in a width x height image of `fov`.
std::pair<double, double> pixelOf(const XrFovf& fov, double tx, double ty, uint32_t width, uint32_t height) {
  const double tl = std::tan(fov.angleLeft), tr = std::tan(fov.angleRight);
  const double tu = std::tan(fov.angleUp), td = std::tan(fov.angleDown);
  return {(tx - tl) / (tr - tl) * width, (tu - ty) / (tu - td) * height};
}

void expectFovNear(const XrFovf& a, const XrFovf& b, float tol) {
  EXPECT_NEAR(a.angleLeft, b.angleLeft, tol);
  EXPECT_NEAR(a.angleRight, b.angleRight, tol);
  EXPECT_NEAR(a.angleUp, b.angleUp, tol);
  EXPECT_NEAR(a.angleDown, b.angleDown, tol);
}

bool sameFov(const XrFovf& a, const XrFovf& b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

// Runs one xrLocateViews-like call through the tracker; returns the jittered fovs.
std::array<XrFovf, 2> locate(JitterTracker& t, const XrFovf& left, const XrFovf& right) {
  std::array<XrFovf, 2> fovs{left, right};
  const std::array<VkExtent2D, 2> sizes{kSize, kSize};
  EXPECT_EQ(t.apply(fovs.data(), sizes.data(), 2), 2u);
  return fovs;
}

const XrFovf kLeft{-0.80f, 0.70f, 0.75f, -0.78f};
const XrFovf kRight{-0.70f, 0.80f, 0.75f, -0.78f};

// A world direction that projects to pixel u under fov projects to u - (dx, dy) under
// jitterFov(fov, dx, dy): the jittered image holds the unjittered pixel c at c - jitterPx,
// which is core::ViewFrame::jitterPx's convention, so jitterPx = (dx, dy).
TEST(Jitter, SignOfThePixelOffset) {
  const float dx = 0.3f, dy = -0.2f;
  const XrFovf j = jitterFov(kLeft, dx, dy, kSize.width, kSize.height);
  for (const auto& [tx, ty] : {std::pair{0.0, 0.0}, std::pair{0.5, -0.3}, std::pair{-0.9, 0.8}}) {
    const auto [u, v] = pixelOf(kLeft, tx, ty, kSize.width, kSize.height);
    const auto [uj, vj] = pixelOf(j, tx, ty, kSize.width, kSize.height);
    EXPECT_NEAR(uj, u - dx, 1e-3) << tx << "," << ty;
    EXPECT_NEAR(vj, v - dy, 1e-3) << tx << "," << ty;
  }
  // The tracker reports the same offset it applied, with that sign.
  JitterTracker t;
  const std::array<XrFovf, 2> jittered = locate(t, kLeft, kRight);
  const ViewUnjitter u = t.find(0, jittered[0], kSize);
  ASSERT_TRUE(u.matched);
  const auto [cu, cv] = pixelOf(kLeft, 0.25, 0.1, kSize.width, kSize.height);        // output pixel c
  const auto [iu, iv] = pixelOf(jittered[0], 0.25, 0.1, kSize.width, kSize.height);  // input pixel
  EXPECT_NEAR(iu, cu - u.jitterPx[0], 1e-3);
  EXPECT_NEAR(iv, cv - u.jitterPx[1], 1e-3);
}

TEST(Jitter, ExactInverse) {
  for (const float d : {-0.5f, -0.25f, 0.125f, 0.4999f}) {
    const XrFovf j = jitterFov(kLeft, d, -d, kSize.width, kSize.height);
    expectFovNear(jitterFov(j, -d, d, kSize.width, kSize.height), kLeft, 1e-6f);
  }
  // The tracker hands back the very fov the runtime returned, not a recomputed one.
  JitterTracker t;
  for (int call = 0; call < 8; ++call) {
    const std::array<XrFovf, 2> j = locate(t, kLeft, kRight);
    const ViewUnjitter l = t.find(0, j[0], kSize), r = t.find(1, j[1], kSize);
    ASSERT_TRUE(l.matched && r.matched);
    EXPECT_TRUE(sameFov(l.fov, kLeft));
    EXPECT_TRUE(sameFov(r.fov, kRight));
    expectFovNear(jitterFov(j[0], -l.jitterPx[0], -l.jitterPx[1], kSize.width, kSize.height), kLeft, 1e-6f);
  }
}

TEST(Jitter, HaltonOffsetsPeriodEight) {
  JitterTracker t;
  std::set<std::pair<float, float>> seen;
  std::array<std::pair<float, float>, 8> first{};
  for (uint32_t call = 0; call < 16; ++call) {
    const std::array<XrFovf, 2> j = locate(t, kLeft, kRight);
    const ViewUnjitter u = t.find(0, j[0], kSize);
    ASSERT_TRUE(u.matched);
    EXPECT_GE(u.jitterPx[0], -0.5f);
    EXPECT_LT(u.jitterPx[0], 0.5f);
    EXPECT_GE(u.jitterPx[1], -0.5f);
    EXPECT_LT(u.jitterPx[1], 0.5f);
    EXPECT_FLOAT_EQ(u.jitterPx[0], halton(call % 8 + 1, 2) - 0.5f);
    EXPECT_FLOAT_EQ(u.jitterPx[1], halton(call % 8 + 1, 3) - 0.5f);
    // Both views of one call share the offset.
    const ViewUnjitter r = t.find(1, j[1], kSize);
    EXPECT_EQ(r.jitterPx[0], u.jitterPx[0]);
    EXPECT_EQ(r.jitterPx[1], u.jitterPx[1]);
    if (call < 8) {
      first[call] = {u.jitterPx[0], u.jitterPx[1]};
      seen.insert(first[call]);
    } else {
      EXPECT_EQ(first[call - 8], std::make_pair(u.jitterPx[0], u.jitterPx[1]));
    }
  }
  EXPECT_EQ(seen.size(), 8u);
}

TEST(Jitter, MatchAndNoMatch) {
  JitterTracker t;
  EXPECT_FALSE(t.find(0, kLeft, kSize).matched);  // nothing recorded yet
  const std::array<XrFovf, 2> older = locate(t, kLeft, kRight);
  const std::array<XrFovf, 2> newer = locate(t, kLeft, kRight);
  EXPECT_EQ(t.recordedCalls(), 2u);

  // An app that submits the previous call's fov (it located twice in one frame) still matches.
  const ViewUnjitter o = t.find(0, older[0], kSize);
  ASSERT_TRUE(o.matched);
  EXPECT_FLOAT_EQ(o.jitterPx[0], halton(1, 2) - 0.5f);
  EXPECT_FLOAT_EQ(o.jitterPx[1], halton(1, 3) - 0.5f);
  const ViewUnjitter n = t.find(0, newer[0], kSize);
  ASSERT_TRUE(n.matched);
  EXPECT_FLOAT_EQ(n.jitterPx[0], halton(2, 2) - 0.5f);
  EXPECT_FLOAT_EQ(n.jitterPx[1], halton(2, 3) - 0.5f);

  // Within the tolerance (1e-6 rad per angle) it matches; beyond it, it does not.
  XrFovf close = newer[0];
  close.angleUp += 5e-7f;
  EXPECT_TRUE(t.find(0, close, kSize).matched);
  XrFovf off = newer[0];
  off.angleDown += 1e-5f;
  const ViewUnjitter none = t.find(0, off, kSize);
  EXPECT_FALSE(none.matched);
  EXPECT_TRUE(sameFov(none.fov, off));  // the app's own fov goes through as is, with no jitter
  EXPECT_EQ(none.jitterPx[0], 0.0f);
  EXPECT_EQ(none.jitterPx[1], 0.0f);

  // The app's unjittered fov, the other view's fov, or a view index past two: no match.
  EXPECT_FALSE(t.find(0, kLeft, kSize).matched);
  EXPECT_FALSE(t.find(1, newer[0], kSize).matched);
  EXPECT_FALSE(t.find(2, newer[0], kSize).matched);
}

TEST(Jitter, RingOverflowForgetsTheOldestCall) {
  JitterTracker t;
  std::vector<std::array<XrFovf, 2>> calls;
  for (uint32_t c = 0; c <= JitterTracker::kCalls; ++c) {  // one call more than remembered
    XrFovf l = kLeft, r = kRight;
    l.angleUp = r.angleUp = 0.6f + 0.01f * static_cast<float>(c);  // distinct originals
    calls.push_back(locate(t, l, r));
  }
  EXPECT_EQ(t.recordedCalls(), JitterTracker::kCalls);
  EXPECT_FALSE(t.find(0, calls[0][0], kSize).matched);
  EXPECT_FALSE(t.find(1, calls[0][1], kSize).matched);
  for (uint32_t c = 1; c < calls.size(); ++c) {
    const ViewUnjitter u = t.find(0, calls[c][0], kSize);
    ASSERT_TRUE(u.matched) << c;
    EXPECT_FLOAT_EQ(u.fov.angleUp, 0.6f + 0.01f * static_cast<float>(c));
  }
}

TEST(Jitter, PixelOffsetFollowsTheSubmittedSize) {
  JitterTracker t;
  locate(t, kLeft, kRight);
  const std::array<XrFovf, 2> j = locate(t, kLeft, kRight);  // call 2: a non-zero x offset
  const ViewUnjitter same = t.find(0, j[0], kSize);
  const ViewUnjitter twice = t.find(0, j[0], {2 * kSize.width, 2 * kSize.height});
  ASSERT_TRUE(same.matched && twice.matched);
  EXPECT_NE(same.jitterPx[0], 0.0f);
  EXPECT_FLOAT_EQ(twice.jitterPx[0], 2.0f * same.jitterPx[0]);
  EXPECT_FLOAT_EQ(twice.jitterPx[1], 2.0f * same.jitterPx[1]);
  // Still the tangent-space shift the fov carries: the direction check at the larger size.
  const auto [cu, cv] = pixelOf(kLeft, 0.1, -0.2, 2 * kSize.width, 2 * kSize.height);
  const auto [iu, iv] = pixelOf(j[0], 0.1, -0.2, 2 * kSize.width, 2 * kSize.height);
  EXPECT_NEAR(iu, cu - twice.jitterPx[0], 2e-3);
  EXPECT_NEAR(iv, cv - twice.jitterPx[1], 2e-3);
}

TEST(Jitter, OddInputIsLeftAlone) {
  JitterTracker t;
  std::array<XrFovf, 3> fovs{kLeft, kRight, kLeft};
  std::array<VkExtent2D, 3> sizes{kSize, kSize, kSize};
  EXPECT_EQ(t.apply(fovs.data(), sizes.data(), 3), 0u);  // more views than the layer filters
  EXPECT_EQ(t.apply(nullptr, sizes.data(), 2), 0u);
  EXPECT_EQ(t.recordedCalls(), 0u);
  EXPECT_TRUE(sameFov(fovs[0], kLeft));

  // A view of unknown size or with a broken fov keeps its fov and never matches.
  XrFovf bad = kRight;
  bad.angleRight = NAN;
  std::array<XrFovf, 2> two{kLeft, bad};
  std::array<VkExtent2D, 2> noSize{VkExtent2D{0, 0}, kSize};
  EXPECT_EQ(t.apply(two.data(), noSize.data(), 2), 0u);
  EXPECT_TRUE(sameFov(two[0], kLeft));
  EXPECT_TRUE(sameFov(two[1], bad));
  EXPECT_FALSE(t.find(0, kLeft, kSize).matched);
  EXPECT_FALSE(t.find(1, bad, kSize).matched);
}

TEST(Jitter, OnlyTemporalMethodsUndoIt) {
  using core::TemporalMethod;
  EXPECT_TRUE(undoesJitter(TemporalMethod::Taa));
  EXPECT_TRUE(undoesJitter(TemporalMethod::Hmtaa));
  EXPECT_TRUE(undoesJitter(TemporalMethod::Vtaa));
  EXPECT_TRUE(undoesJitter(TemporalMethod::Hybrid));
  EXPECT_TRUE(undoesJitter(core::kDefaultTemporalMethod));
  EXPECT_FALSE(undoesJitter(TemporalMethod::None));  // also "stereo" alone
  EXPECT_FALSE(undoesJitter(TemporalMethod::Fxaa));
}

// The frame the runtime gets carries the unjittered fov; the app's structs keep the jittered one.
TEST(Jitter, RewrittenFrameCarriesTheUnjitteredFov) {
  JitterTracker t;
  locate(t, kLeft, kRight);
  const std::array<XrFovf, 2> j = locate(t, kLeft, kRight);
  const XrSwapchain app = reinterpret_cast<XrSwapchain>(uintptr_t{1});
  const XrSwapchain out = reinterpret_cast<XrSwapchain>(uintptr_t{2});
  std::array<XrCompositionLayerProjectionView, 2> views{};
  for (uint32_t i = 0; i < 2; ++i) {
    views[i] = makeXr<XrCompositionLayerProjectionView>(XR_TYPE_COMPOSITION_LAYER_PROJECTION_VIEW);
    views[i].pose.orientation.w = 1.0f;
    views[i].fov = j[i];
    views[i].subImage.swapchain = app;
    views[i].subImage.imageRect = {{0, 0}, {320, 240}};
    views[i].subImage.imageArrayIndex = i;
  }
  const std::array<XrCompositionLayerProjectionView, 2> before = views;
  auto proj = makeXr<XrCompositionLayerProjection>(XR_TYPE_COMPOSITION_LAYER_PROJECTION);
  proj.viewCount = 2;
  proj.views = views.data();
  const XrCompositionLayerBaseHeader* layers[] = {
      reinterpret_cast<const XrCompositionLayerBaseHeader*>(&proj)};
  auto info = makeXr<XrFrameEndInfo>(XR_TYPE_FRAME_END_INFO);
  info.layerCount = 1;
  info.layers = layers;

  std::vector<XrFovf> fovs;
  for (uint32_t i = 0; i < 2; ++i) {
    const ViewUnjitter u = t.find(i, views[i].fov, kSize);
    ASSERT_TRUE(u.matched);
    fovs.push_back(u.fov);
  }
  FrameRewrite rw(info);
  rw.replaceProjection(0, {out, out}, &fovs);
  const auto* copy = reinterpret_cast<const XrCompositionLayerProjection*>(rw.info().layers[0]);
  EXPECT_TRUE(sameFov(copy->views[0].fov, kLeft));
  EXPECT_TRUE(sameFov(copy->views[1].fov, kRight));
  EXPECT_EQ(copy->views[1].subImage.swapchain, out);
  // The app's structs are untouched: still the jittered fov, its own swapchain.
  EXPECT_EQ(std::memcmp(views.data(), before.data(), sizeof views), 0);
  EXPECT_TRUE(sameFov(views[0].fov, j[0]));
  EXPECT_FALSE(sameFov(views[0].fov, kLeft));
  EXPECT_EQ(info.layers[0], layers[0]);
}

}  // namespace
}  // namespace steadyxr::layer
