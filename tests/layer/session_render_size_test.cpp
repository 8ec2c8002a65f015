// The app's render size and rect placement, through a Session on real Vulkan (lavapipe) behind the fake
// runtime: dynamic resolution keeps steady's history, a growing rect takes the memory of its own part of the
// image, and rects that move inside the image keep the history, side by side and one above the other.
#include "session_app.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <utility>
#include <vector>

namespace steadyxr::layer {
namespace {

using namespace session_rig;

// The whole of an app image of `layout` in one colour.
test::HostImage imageOf(Layout layout, glm::vec4 colour) {
  return layout == Layout::Stacked ? test::HostImage(32, 64, colour) : test::HostImage(64, 32, colour);
}

// Frame k of a still picture (smooth ramps and a hard-edged square) with fresh noise, drawn into each of
// `app`'s view rects where they are now; grey elsewhere.
test::HostImage viewsAt(const App& app, uint32_t k) {
  test::HostImage img = imageOf(app.layout_, glm::vec4(0.5f, 0.5f, 0.5f, 1.0f));
  std::mt19937 rng(100 + k);
  std::uniform_real_distribution<float> noise(-0.06f, 0.06f);
  for (uint32_t v = 0; v < 2; ++v) {
    const XrOffset2Di at = app.rectOffset(v);
    for (int32_t y = 0; y < app.renderSize; ++y)
      for (int32_t x = 0; x < app.renderSize; ++x) {
        const bool square = x >= 6 && x < 15 && y >= 9 && y < 18;
        const glm::vec3 picture = square ? glm::vec3(0.9f, 0.2f, 0.1f)
                                         : glm::vec3(0.2f + 0.02f * float(x), 0.3f + 0.015f * float(y), 0.4f);
        const glm::vec3 c = picture + glm::vec3(noise(rng), noise(rng), noise(rng));
        img.at(uint32_t(at.x + x), uint32_t(at.y + y)) = glm::vec4(glm::clamp(c, 0.0f, 1.0f), 1.0f);
      }
  }
  return img;
}

// The size x size square of `img` at `at`.
test::HostImage cropOf(const test::HostImage& img, XrOffset2Di at, int32_t size) {
  test::HostImage crop{uint32_t(size), uint32_t(size)};
  for (uint32_t y = 0; y < crop.height; ++y)
    for (uint32_t x = 0; x < crop.width; ++x) crop.at(x, y) = img.at(uint32_t(at.x) + x, uint32_t(at.y) + y);
  return crop;
}

float largestDifference(const test::HostImage& a, const test::HostImage& b) {
  float worst = 0.0f;
  for (size_t i = 0; i < a.px.size(); ++i)
    for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(a.px[i][c] - b.px[i][c]));
  return worst;
}

class RenderSizeLayouts : public SessionTest, public ::testing::WithParamInterface<Layout> {};

// Dynamic resolution: an app that renders a smaller or larger part of its swapchain from one frame to the
// next (up to the size it started at) keeps steady's history: after four grey frames at one size, the
// checker at another differs from steady's checker without a history (after a loading screen), at 24 px
// after 32 and at 32 after 24. (Its fresh start where the pose does not explain a frame, and the gain that
// would relight the grey, are off: they would take the grey out at the checker's first frame whatever the
// size.) Plain taa starts afresh at each change, and blends the grey in where the size stays.
TEST_F(SessionTest, HistoryIsKeptWhenTheAppChangesItsRenderSize) {
  const test::HostImage grey(64, 32, glm::vec4(0.5f, 0.5f, 0.5f, 1.0f));
  test::HostImage checker(64, 32);
  for (uint32_t y = 0; y < 32; ++y)
    for (uint32_t x = 0; x < 64; ++x) checker.at(x, y) = glm::vec4(glm::vec3(float((x + y) % 2)), 1.0f);
  // Four grey frames at greySize, then (after `between`) the checker at checkerSize: what is shown.
  const auto checkerAfterGrey = [&](App& app, FakeRuntime& fake, int32_t greySize, int32_t checkerSize,
                                    const std::function<void()>& between) {
    app.content = grey;
    app.renderSize = greySize;
    for (int i = 0; i < 4; ++i) EXPECT_EQ(app.frame(), XR_SUCCESS);
    between();
    app.content = checker;
    app.renderSize = checkerSize;
    EXPECT_EQ(app.frame(), XR_SUCCESS);
    EXPECT_NE(fake.lastSubmittedSwapchain, app.swapchain_);  // filtered
    return app.shown();
  };
  // The largest difference inside both views' rects of `size` (the rest is not shown).
  const auto differenceIn = [](const test::HostImage& a, const test::HostImage& b, int32_t size) {
    float worst = 0.0f;
    for (uint32_t v = 0; v < 2; ++v)
      for (uint32_t y = 0; y < uint32_t(size); ++y)
        for (uint32_t x = 32 * v; x < 32 * v + uint32_t(size); ++x)
          for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(a.at(x, y)[c] - b.at(x, y)[c]));
    return worst;
  };
  {
    FakeRuntime fake(*gVk);
    Config cfg;
    cfg.method = "steady";
    cfg.params.steadyUnexplainedFrameResets = false;
    cfg.params.steadyGainCompensation = false;
    App app(fake, cfg);
    app.content = grey;
    ASSERT_TRUE(app.warmUp());
    for (const auto& [greySize, checkerSize] : {std::pair{32, 24}, std::pair{24, 32}}) {
      const test::HostImage fresh =
          checkerAfterGrey(app, fake, greySize, checkerSize, [&] { app.emptyFrame(); });
      const test::HostImage kept = checkerAfterGrey(app, fake, greySize, checkerSize, [] {});
      EXPECT_GT(differenceIn(kept, fresh, checkerSize), 0.1f) << greySize << " px, then " << checkerSize;
    }
    EXPECT_EQ(app.session_->stats().historyDropped, 2u);  // the loading screens only
  }
  FakeRuntime fake(*gVk);
  Config cfg;
  cfg.method = "taa";  // without a history: the checker as it is
  App app(fake, cfg);
  app.content = grey;
  ASSERT_TRUE(app.warmUp());
  EXPECT_GT(differenceIn(checkerAfterGrey(app, fake, 32, 32, [] {}), checker, 32), 0.2f);  // blended
  EXPECT_LE(differenceIn(checkerAfterGrey(app, fake, 32, 24, [] {}), checker, 24), 1.0f / 255.0f);
}

// An eye's rect that grows reallocates the filter's images once, to the largest rect the image holds at that
// offset short of the other eye's part: the same memory as an app that rendered at the full size from the
// start. Without the bound the first eye's images would span both parts (1.5x the memory), side by side
// and one above the other.
TEST_P(RenderSizeLayouts, AGrowingRectStopsAtTheOtherEye) {
  const Layout layout = GetParam();
  // After warming up at the first size, one frame at each size: the filter's image memory, its reallocations.
  const auto memoryAfter = [&](const std::vector<int32_t>& sizes) -> std::pair<uint64_t, uint64_t> {
    FakeRuntime fake(*gVk);
    Config cfg;
    cfg.method = "steady";
    App app(fake, cfg, true, VK_FORMAT_R8G8B8A8_UNORM, layout);
    app.content = imageOf(layout, glm::vec4(0.5f, 0.5f, 0.5f, 1.0f));
    app.renderSize = sizes.front();
    if (!app.warmUp()) return {0, 0};
    for (int32_t size : sizes) {
      app.renderSize = size;
      EXPECT_EQ(app.frame(), XR_SUCCESS);
    }
    const SessionStats stats = app.session_->stats();
    return {stats.imageMemoryBytes, stats.renderSize.imagesReallocated};
  };
  const auto [fullBytes, fullReallocated] = memoryAfter({32});
  const auto [grownBytes, grownReallocated] = memoryAfter({24, 32, 28});
  EXPECT_GT(fullBytes, 0u);
  EXPECT_EQ(fullReallocated, 0u);
  EXPECT_EQ(grownReallocated, 1u);
  EXPECT_EQ(grownBytes, fullBytes) << "after growing from 24 px to 32 px in each part of the image";
}

// An app that moves its rects inside the image from frame to frame (keeping their size) keeps steady's
// history: what is shown in each view's rect is, to the bit, what an app whose rects stay put is shown.
// (The history lives in the rect's own pixels; only the reads of the input and the writes of the output
// follow the offset.) Each frame is a still picture with fresh noise, so the history visibly averages it:
// an app that drops the history at every frame (a loading screen between frames) is shown something else.
TEST_P(RenderSizeLayouts, RectsThatMoveKeepTheHistory) {
  const Layout layout = GetParam();
  constexpr int32_t kSize = 24;  // each view's rect, moved by up to 8 px inside its 32-px part
  const std::vector<XrOffset2Di> still{{0, 0}}, moving{{0, 0}, {8, 8}, {3, 5}, {8, 0}, {1, 7}};
  // Frames 1..8 with the rects at `shifts` (in turn): each view's rect as shown, frame by frame.
  const auto shownRects = [&](const std::vector<XrOffset2Di>& shifts, bool dropEachFrame) {
    FakeRuntime fake(*gVk);
    Config cfg;
    cfg.method = "steady";
    App app(fake, cfg, true, VK_FORMAT_R8G8B8A8_UNORM, layout);
    app.renderSize = kSize;
    app.content = viewsAt(app, 0);
    EXPECT_TRUE(app.warmUp());  // at the first shift, whose one filtered frame starts the history
    std::vector<test::HostImage> shown;
    for (uint32_t k = 1; k <= 8; ++k) {
      if (dropEachFrame) app.emptyFrame();
      app.shift = shifts[k % shifts.size()];
      app.content = viewsAt(app, k);
      EXPECT_EQ(app.frame(), XR_SUCCESS);
      EXPECT_NE(fake.lastSubmittedSwapchain, app.swapchain_);  // filtered
      const test::HostImage out = app.shown();
      for (uint32_t v = 0; v < 2; ++v) shown.push_back(cropOf(out, app.rectOffset(v), kSize));
    }
    return shown;
  };
  const auto stayed = shownRects(still, false);
  const auto moved = shownRects(moving, false);
  const auto dropped = shownRects(moving, true);
  ASSERT_EQ(moved.size(), stayed.size());
  for (size_t i = 0; i < moved.size(); ++i) {
    EXPECT_EQ(largestDifference(moved[i], stayed[i]), 0.0f) << "frame " << i / 2 + 1 << ", view " << i % 2;
    EXPECT_GT(largestDifference(dropped[i], stayed[i]), 0.02f) << "frame " << i / 2 + 1 << ", view " << i % 2;
  }
}

INSTANTIATE_TEST_SUITE_P(Layouts, RenderSizeLayouts, ::testing::Values(Layout::SideBySide, Layout::Stacked),
                         [](const ::testing::TestParamInfo<Layout>& layoutInfo) {
                           return std::string(layoutInfo.param == Layout::Stacked ? "OneAboveTheOther"
                                                                                  : "SideBySide");
                         });

}  // namespace
}  // namespace steadyxr::layer
