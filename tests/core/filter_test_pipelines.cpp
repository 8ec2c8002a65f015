// Pipeline variants that must give the same images (4x4 blocks and one pixel per invocation,
// the jittered fetch at zero jitter) and the background compile.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <thread>

#include "filter_test_rig.h"

using namespace steadyxr;
using namespace steadyxr::core;
using namespace steadyxr::test;

// Params::invocationBlock: a CPU device runs every pass but fxaa 4x4 pixels per invocation, a GPU
// one pixel. Both layouts must give the same images, on sizes that do not divide by the block (and
// one smaller than a block), on the copy and every temporal mode, with depth (stereo reads both
// eyes' depth).
TEST_F(CoreTest, OnePixelAndBlockInvocationsAgree) {
  for (const auto& [W, H] : {std::pair<uint32_t, uint32_t>{45, 37}, {3, 2}})
    for (const char* method : {"none", "taa+stereo", "hmtaa", "vtaa", "hybrid+stereo"}) {
      std::array<std::array<HostImage, 2>, 2> outs;
      for (int b = 0; b < 2; ++b) {
        Params base;
        base.invocationBlock = b == 0 ? InvocationBlock::OnePixel : InvocationBlock::FourByFour;
        auto f = makeFilter(method, base);
        ASSERT_TRUE(f);
        Rig rig(W, H);
        for (int i = 0; i < 3; ++i) {
          Frame fr;
          const float yaw = 0.6f * float(i);
          fr.views = {eye(yaw, 0.2f * float(i), {-0.032f, 0, 0}), eye(yaw, 0.2f * float(i), {0.032f, 0, 0})};
          fr.color = {pattern(W, H, 40u + 2u * uint32_t(i), 0.1f),
                      pattern(W, H, 41u + 2u * uint32_t(i), 0.1f)};
          for (int e = 0; e < 2; ++e) {
            fr.depth[e] = HostImage(W, H);
            for (uint32_t y = 0; y < H; ++y)
              for (uint32_t x = 0; x < W; ++x) fr.depth[e].at(x, y) = glm::vec4(x < W / 2 ? 0.9f : 0.99f);
          }
          fr.headSpeed = 6.0f;
          outs[size_t(b)] = rig.run(*f, fr);
        }
      }
      for (int e = 0; e < 2; ++e) {
        const Diff d = compare(outs[0][size_t(e)], outs[1][size_t(e)]);
        EXPECT_LE(d.maxAbs, 1e-6f) << method << " " << W << "x" << H << " eye " << e;  // same arithmetic
      }
    }
}

// Params::jitteredInput: the un-jittering fetch at a jitter of 0 reads the texel itself, so the
// layer can use that one pipeline from the first frame on.
TEST_F(CoreTest, JitteredInputWithZeroJitterMatchesPlainFetch) {
  const uint32_t W = 36, H = 28;
  Params jittered;
  jittered.jitteredInput = true;
  auto plain = makeFilter("hybrid+stereo");
  auto withJitterPath = makeFilter("hybrid+stereo", jittered);
  ASSERT_TRUE(plain && withJitterPath);
  Rig rigA(W, H), rigB(W, H);
  for (int i = 0; i < 3; ++i) {
    Frame fr;
    fr.views = {eye(0.4f * float(i), 0.0f, {-0.032f, 0, 0}), eye(0.4f * float(i), 0.0f, {0.032f, 0, 0})};
    fr.color = {pattern(W, H, 70u + uint32_t(i), 0.1f), pattern(W, H, 80u + uint32_t(i), 0.1f)};
    fr.headSpeed = 5.0f;
    const auto a = rigA.run(*plain, fr);
    const auto b = rigB.run(*withJitterPath, fr);
    for (int e = 0; e < 2; ++e) {
      const Diff d = compare(a[size_t(e)], b[size_t(e)]);
      // llvmpipe's bilinear path rounds differently from texelFetch: 1-2 half-float ulps, well
      // below an 8-bit display step (3.9e-3).
      EXPECT_LE(d.maxAbs, 2e-3f) << "frame " << i << " eye " << e;
      EXPECT_LE(d.meanAbs, 2e-4f) << "frame " << i << " eye " << e;
    }
  }
}

// FilterOptions::compileInBackground: frames are refused (compiling() true, the caller passes them
// through) until the pipelines are ready, and never stall for the compile; the first filtered
// frame then matches a synchronously compiled filter's first frame. Filters on one context share
// their pipelines (VulkanContext's pipeline store).
TEST_F(CoreTest, BackgroundCompileRefusesFramesUntilReady) {
  const uint32_t W = 40, H = 32;
  const Params p = *applyMethodName("default");
  std::string err;
  // A context of its own: on the suite's, an earlier test may have compiled the default's pipelines
  // already, and every filter on a context shares them.
  OwnedContextOptions options;
  options.enableValidation = true;
  auto fresh = VulkanContext::createOwned(options, &err);
  ASSERT_TRUE(fresh) << err;
  FilterOptions background;
  background.compileInBackground = true;
  auto f = Filter::create(*fresh, p, &err, background);
  ASSERT_TRUE(f) << err;
  auto reference = Filter::create(*gCtx, p, &err);
  ASSERT_TRUE(reference) << err;
  Rig rig(*fresh, W, H), referenceRig(W, H);
  Frame fr;
  fr.views = {eye(0.3f, 0.1f, {-0.032f, 0, 0}), eye(0.3f, 0.1f, {0.032f, 0, 0})};
  fr.color = {pattern(W, H, 61, 0.05f), pattern(W, H, 62, 0.05f)};
  fr.headSpeed = 3.0f;

  bool submitted = true;
  rig.run(*f, fr, 2, &submitted);
  EXPECT_FALSE(submitted);
  EXPECT_TRUE(f->compiling());
  std::array<HostImage, 2> out;
  for (int i = 0; i < 6000 && !submitted; ++i) {  // a minute at most
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    out = rig.run(*f, fr, 2, &submitted);
  }
  ASSERT_TRUE(submitted);
  EXPECT_FALSE(f->compiling());
  const auto want = referenceRig.run(*reference, fr);
  for (int e = 0; e < 2; ++e) {
    const Diff d = compare(out[size_t(e)], want[size_t(e)]);
    EXPECT_LE(d.maxAbs, 1e-6f) << "eye " << e;
  }

  // The pipelines are the context's: a second filter there filters its first frame at once, and lists
  // only the pipelines it used itself (not the first filter's when its method needs others).
  auto second = Filter::create(*fresh, p, &err, background);
  ASSERT_TRUE(second) << err;
  Rig secondRig(*fresh, W, H);
  const auto again = secondRig.run(*second, fr, 2, &submitted);
  EXPECT_TRUE(submitted) << "the second filter compiled its pipelines again";
  for (int e = 0; e < 2; ++e)
    EXPECT_LE(compare(again[size_t(e)], want[size_t(e)]).maxAbs, 1e-6f) << "eye " << e;
  auto copyOnly = Filter::create(*fresh, *applyMethodName("none"), &err, background);
  ASSERT_TRUE(copyOnly) << err;
  Rig copyRig(*fresh, W, H);
  for (int i = 0; i < 6000; ++i) {
    copyRig.run(*copyOnly, fr, 2, &submitted);
    if (submitted) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_TRUE(submitted);
  for (const PipelineDescription& d : copyOnly->pipelines()) EXPECT_EQ(d.pass, "copy");
  EXPECT_FALSE(copyOnly->pipelines().empty());
  EXPECT_GT(f->pipelines().size(), copyOnly->pipelines().size());
  EXPECT_EQ(fresh->validationMessageCount(), 0u)
      << "validation: " << (fresh->validationMessages().empty() ? "" : fresh->validationMessages().front());
}

// The default filters a frame only once both of its probes are made (round 44): the plain probe that most
// frames run, and the head-locked switch's, which the frames that start or end an epoch run and which may
// be missing (the switch then skips the epoch). Worker threads finish the two in any order. When the
// switch's came first, the frames that started an epoch were filtered and the frames after them passed
// through while the plain probe compiled, each restarting the history and the epochs: filtered and passed
// through in turn at a session's start (and, on a loaded machine, a layer session test that failed at
// times). The test holds each probe back in turn (FilterOptions::holdBackForTests) under a still head,
// whose every other frame starts an epoch while frames pass through.
TEST_F(CoreTest, FramesWaitForThePlainProbeButNotForTheHeadLockedOne) {
  const uint32_t W = 40, H = 32;
  constexpr int32_t kProbeBit = 128, kObservationBit = 8192;  // passSpecKey's, in specialisation[14]
  const auto isProbe = [&](const PipelineDescription& d, bool observing) {
    return d.pass == "temporal" && d.specialisation.size() == 15 && (d.specialisation[14] & kProbeBit) != 0 &&
           ((d.specialisation[14] & kObservationBit) != 0) == observing;
  };
  const auto made = [&](const Filter& f, bool observing) {
    const auto pipelines = f.pipelines();
    return std::any_of(pipelines.begin(), pipelines.end(),
                       [&](const auto& d) { return isProbe(d, observing); });
  };
  const auto writesOutput = [](const Filter& f) {
    const auto pipelines = f.pipelines();
    return std::any_of(pipelines.begin(), pipelines.end(), [](const PipelineDescription& d) {
      return d.pass == "temporal" && d.specialisation.size() == 15 && d.specialisation[2] == 1;
    });
  };
  Frame fr;
  fr.views = {eye(0.3f, 0.1f, {-0.032f, 0, 0}), eye(0.3f, 0.1f, {0.032f, 0, 0})};
  fr.color = {pattern(W, H, 71), pattern(W, H, 72)};
  const Params p = *applyMethodName("default");
  ASSERT_TRUE(p.steadyHeadLockedSwitch);
  std::string err;

  // The plain probe held back: no frame is filtered, also once the switch's probe and the pass are made.
  bool holdPlain = true;
  FilterOptions options;
  options.compileInBackground = true;
  options.holdBackForTests = [&](const PipelineDescription& d) { return holdPlain && isProbe(d, false); };
  auto f = Filter::create(*gCtx, p, &err, options);
  ASSERT_TRUE(f) << err;
  Rig rig(W, H);
  bool submitted = false;
  int filtered = 0;
  for (int i = 0; i < 6000 && !(made(*f, true) && writesOutput(*f)); ++i) {  // a minute at most
    rig.run(*f, fr, 2, &submitted);
    filtered += submitted ? 1 : 0;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_TRUE(made(*f, true) && writesOutput(*f));
  for (int i = 0; i < 8; ++i) {
    rig.run(*f, fr, 2, &submitted);
    filtered += submitted ? 1 : 0;
  }
  EXPECT_EQ(filtered, 0) << "frames filtered while the plain probe was still compiling";
  EXPECT_TRUE(f->compiling());
  holdPlain = false;  // made: from the next frame on, every frame is filtered
  for (int i = 0; i < 8; ++i) {
    rig.run(*f, fr, 2, &submitted);
    EXPECT_TRUE(submitted) << "frame " << i << " after the plain probe was made";
  }

  // The switch's probe held back: frames are filtered without it (the epochs wait), every one.
  FilterOptions withoutSwitch;
  withoutSwitch.compileInBackground = true;
  withoutSwitch.holdBackForTests = [&](const PipelineDescription& d) { return isProbe(d, true); };
  auto g = Filter::create(*gCtx, p, &err, withoutSwitch);
  ASSERT_TRUE(g) << err;
  Rig other(W, H);
  submitted = false;
  for (int i = 0; i < 6000 && !submitted; ++i) {
    other.run(*g, fr, 2, &submitted);
    if (!submitted) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_TRUE(submitted);
  for (int i = 0; i < 8; ++i) {
    other.run(*g, fr, 2, &submitted);
    EXPECT_TRUE(submitted) << "frame " << i << " without the head-locked switch's probe";
  }
  EXPECT_TRUE(made(*g, false));
  EXPECT_FALSE(made(*g, true));
}

// Round 45: an app whose frames start or stop giving depth half-way. With Filter::setDepthMayChange (the
// layer sets it once the app has a depth swapchain) each filtered frame asks for its pipelines' twins with
// depth the other way, and a frame that changes finds them made instead of passing through while they compile
// (which also restarts the history). Without it, the first frame with depth waits: what no depth swapchain
// predicts.
TEST_F(CoreTest, DepthThatStartsOrStopsHalfWayFindsItsPipelinesMade) {
  const uint32_t W = 40, H = 32;
  constexpr size_t kDepthBits = 6;           // passSpecKey's order
  constexpr int32_t kObservationBit = 8192;  // in specialisation[14]: the switch's probe
  Frame plain;
  plain.views = {eye(0.3f, 0.1f, {-0.032f, 0, 0}), eye(0.3f, 0.1f, {0.032f, 0, 0})};
  plain.color = {pattern(W, H, 81), pattern(W, H, 82)};
  Frame deep = plain;
  deep.depth = {HostImage(W, H, glm::vec4(0.9f)), HostImage(W, H, glm::vec4(0.9f))};
  // Every pipeline made with depth `from` has its twin with depth the other way; but the head-locked switch's
  // probe, which no frame waits for (its twin is asked for in the next epoch's frame).
  const auto twinsMade = [&](const Filter& f, bool from) {
    std::vector<std::vector<int32_t>> with[2];
    for (const PipelineDescription& d : f.pipelines()) {
      if (d.specialisation.size() != 15 ||
          (d.pass == "temporal" && (d.specialisation[14] & kObservationBit) != 0))
        continue;
      std::vector<int32_t> key = d.specialisation;
      key.push_back(d.pass == "stereo" ? 1 : 0);
      const bool hasDepth = key[kDepthBits] != 0;
      key[kDepthBits] = 0;
      with[hasDepth ? 1 : 0].push_back(key);
    }
    return !with[from].empty() && std::all_of(with[from].begin(), with[from].end(), [&](const auto& k) {
      return std::find(with[!from].begin(), with[!from].end(), k) != with[!from].end();
    });
  };
  FilterOptions options;
  options.compileInBackground = true;
  std::string err;
  // Each part on a context of its own: filters on one context share their pipelines, so an earlier part's (or
  // test's) would already be made.
  const auto freshContext = [&] {
    OwnedContextOptions contextOptions;
    contextOptions.enableValidation = true;
    return VulkanContext::createOwned(contextOptions, &err);
  };
  // The default either way, and plain taa with the stereo pass, which reads both eyes' depth (steady's stereo
  // pass runs without depth only where the disparity is known to a pixel, so a frame with depth can add the
  // pass, which is no twin of a pass that ran: not prepared, left out here).
  for (const auto& [method, startWithDepth] :
       {std::pair<const char*, bool>{"default", false}, {"default", true}, {"taa+stereo", false}}) {
    auto context = freshContext();
    ASSERT_TRUE(context) << err;
    auto f = Filter::create(*context, *applyMethodName(method), &err, options);
    ASSERT_TRUE(f) << err;
    f->setDepthMayChange(true);
    Rig rig(*context, W, H);
    bool submitted = false;
    for (int i = 0; i < 6000 && !(submitted && twinsMade(*f, startWithDepth)); ++i) {  // a minute at most
      rig.run(*f, startWithDepth ? deep : plain, 2, &submitted);
      if (!submitted) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    ASSERT_TRUE(submitted && twinsMade(*f, startWithDepth))
        << method << ", start with depth " << startWithDepth;
    for (int i = 0; i < 6; ++i) {
      rig.run(*f, startWithDepth ? plain : deep, 2, &submitted);
      EXPECT_TRUE(submitted) << method << ", frame " << i << " after depth "
                             << (startWithDepth ? "stopped" : "started");
    }
  }

  // Without it, nothing but the frames' own pipelines is made: the first frame with depth waits for its own.
  auto context = freshContext();
  ASSERT_TRUE(context) << err;
  auto g = Filter::create(*context, *applyMethodName("default"), &err, options);
  ASSERT_TRUE(g) << err;
  Rig rig(*context, W, H);
  bool submitted = false;
  for (int i = 0; i < 6000 && !submitted; ++i) {
    rig.run(*g, plain, 2, &submitted);
    if (!submitted) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_TRUE(submitted);
  for (int i = 0; i < 3; ++i) rig.run(*g, plain, 2, &submitted);
  EXPECT_FALSE(twinsMade(*g, false));
  rig.run(*g, deep, 2, &submitted);
  EXPECT_FALSE(submitted);
  EXPECT_TRUE(g->compiling());
}
