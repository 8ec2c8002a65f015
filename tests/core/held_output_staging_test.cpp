// Round 40: where the passes run 4x4 pixels an invocation (a CPU device), the held 8-bit output's codes image
// is also the output's staging image: the pass stores the codes once, and a transfer copy takes them to the
// app's image (Filter::Impl::stagesHeldOutput). The app must get what the direct path gives it (the pass
// storing to the app's image and to the codes image apart): the same codes, in the app's channel order, and
// the app's alpha. The direct path here is the one-pixel invocation's (a GPU's), whose arithmetic is the
// blocks' (CoreTest.OnePixelAndBlockInvocationsAgree).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include "filter_test_rig.h"

using namespace steadyxr;
using namespace steadyxr::core;
using namespace steadyxr::test;

namespace {

constexpr uint32_t kW = 21, kH = 13;  // neither a multiple of the 4x4 blocks
constexpr int kFrames = 10;

// Colour ramps a code apart per channel, each with a one-code checker that swaps every frame (aliasing under
// a still head, which the hold keeps steady), red and blue unlike each other so that a swapped read shows;
// the alpha a code per pixel, which every output must carry exactly.
HostImage checkerFrame(int k) {
  HostImage img(kW, kH);
  for (uint32_t y = 0; y < kH; ++y)
    for (uint32_t x = 0; x < kW; ++x) {
      const int flip = int((x + y + uint32_t(k)) % 2);
      img.at(x, y) = glm::vec4(float(60 + int(x) / 3 + flip), float(140 + int(y) / 2 + flip),
                               float(200 - int(x + y) / 4 + flip), float(40 + 9 * x + y)) /
                     255.0f;
    }
  return img;
}

Params heldDefault(InvocationBlock block, float hold) {
  Params p = *applyMethodName("default");
  p.invocationBlock = block;
  p.steadyOutputHold = hold;
  return p;
}

// Whether the filter compiled the temporal pass that writes its output into the codes image (switch bit 12).
bool stagedPipelineMade(const Filter& f) {
  for (const PipelineDescription& d : f.pipelines())
    if (d.pass == "temporal" && d.specialisation.size() == 15 && (d.specialisation[14] & 4096) != 0)
      return true;
  return false;
}

}  // namespace

TEST_F(CoreTest, HeldOutputStagedInItsCodesImageMatchesTheDirectPath) {
  for (const VkFormat out : {VK_FORMAT_R8G8B8A8_SRGB, VK_FORMAT_B8G8R8A8_SRGB, VK_FORMAT_R8G8B8A8_UNORM,
                             VK_FORMAT_B8G8R8A8_UNORM}) {
    SCOPED_TRACE(testing::Message() << "output format " << out);
    // The passes store through an RGBA8 UNORM view of any other format.
    const bool viaUnormView = out != VK_FORMAT_R8G8B8A8_UNORM;
    auto staged = makeFilter("default", heldDefault(InvocationBlock::FourByFour, 0.25f));
    auto direct = makeFilter("default", heldDefault(InvocationBlock::OnePixel, 0.25f));
    auto rounded = makeFilter("default", heldDefault(InvocationBlock::FourByFour, 0.0f));
    ASSERT_TRUE(staged && direct && rounded);
    Rig stagedRig(kW, kH, VK_FORMAT_R8G8B8A8_UNORM, out, VK_IMAGE_USAGE_STORAGE_BIT, viaUnormView),
        directRig(kW, kH, VK_FORMAT_R8G8B8A8_UNORM, out, VK_IMAGE_USAGE_STORAGE_BIT, viaUnormView),
        roundedRig(kW, kH, VK_FORMAT_R8G8B8A8_UNORM, out, VK_IMAGE_USAGE_STORAGE_BIT, viaUnormView);
    int mismatches = 0, alphaMismatches = 0, heldChannels = 0;
    for (int k = 0; k < kFrames; ++k) {
      const HostImage img = checkerFrame(k);
      // A head that holds still but for a tremor of a few hundredths of a degree (hundredths of a pixel).
      const Frame frame{
          {img, img},
          {eye(0.02f * std::sin(1.7f * float(k)), 0.015f * std::cos(1.1f * float(k)), {-0.032f, 0, 0}),
           eye(0.02f * std::sin(1.7f * float(k)), 0.015f * std::cos(1.1f * float(k)), {0.032f, 0, 0})}};
      const auto a = stagedRig.run(*staged, frame), b = directRig.run(*direct, frame),
                 c = roundedRig.run(*rounded, frame);
      for (size_t e = 0; e < 2; ++e)
        for (size_t i = 0; i < a[e].px.size(); ++i) {
          for (int ch = 0; ch < 3; ++ch) {
            mismatches += a[e].px[i][ch] != b[e].px[i][ch] ? 1 : 0;
            heldChannels += a[e].px[i][ch] != c[e].px[i][ch] ? 1 : 0;
          }
          alphaMismatches += std::lround(255.0f * a[e].px[i].a) != std::lround(255.0f * img.px[i].a) ? 1 : 0;
        }
    }
    EXPECT_EQ(mismatches, 0) << "channels where the staged output differs from the direct path's";
    EXPECT_EQ(alphaMismatches, 0) << "pixels whose alpha is not the app's";
    // The hold must act, or a staged path that lost last frame's codes would pass (measured: 2892 of the
    // 16380 channels with an sRGB output, 3710 with UNORM).
    EXPECT_GT(heldChannels, 1000) << "channels where the held output differs from plain rounding";
    EXPECT_TRUE(stagedPipelineMade(*staged)) << "the blocks did not stage the output";
    EXPECT_FALSE(stagedPipelineMade(*direct)) << "one pixel an invocation staged the output";
  }
}

// The staged codes are in the app's channel order, so where an eye's output changes between RGBA and BGRA
// (an app that moves to another swapchain), last frame's codes are not read in the other order: that frame
// rounds, as plain rounding does (the hold never touches the history, so both filters hold the same
// estimate), and the frames after it hold again.
TEST_F(CoreTest, HeldOutputRoundsWhereTheAppsChannelOrderChanged) {
  auto held = makeFilter("default", heldDefault(InvocationBlock::FourByFour, 0.25f));
  auto rounded = makeFilter("default", heldDefault(InvocationBlock::FourByFour, 0.0f));
  ASSERT_TRUE(held && rounded);
  const VkImageUsageFlags storage = VK_IMAGE_USAGE_STORAGE_BIT;
  Rig rgba(kW, kH, VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_R8G8B8A8_UNORM, storage, false),
      bgra(kW, kH, VK_FORMAT_R8G8B8A8_UNORM, VK_FORMAT_B8G8R8A8_UNORM, storage, true);
  constexpr int kSwitch = 5;
  std::vector<int> differ(kFrames, 0);  // channels where the held output is not plain rounding's
  for (int k = 0; k < kFrames; ++k) {
    const HostImage img = checkerFrame(k);
    const Frame frame{{img, img}, {eye(0, 0, {-0.032f, 0, 0}), eye(0, 0, {0.032f, 0, 0})}};
    Rig& rig = k < kSwitch ? rgba : bgra;
    const auto a = rig.run(*held, frame), b = rig.run(*rounded, frame);
    for (size_t e = 0; e < 2; ++e)
      for (size_t i = 0; i < a[e].px.size(); ++i)
        for (int ch = 0; ch < 3; ++ch) differ[size_t(k)] += a[e].px[i][ch] != b[e].px[i][ch] ? 1 : 0;
  }
  EXPECT_EQ(differ[kSwitch], 0) << "the frame the order changed kept codes read in the other order";
  // The hold acts before and after it (measured: 52 channels the frame after, 110-550 in the others).
  EXPECT_GT(differ[kSwitch - 1], 100) << "the hold did not act in RGBA";
  EXPECT_GT(differ[kFrames - 1], 100) << "the hold did not act again in BGRA";
}
