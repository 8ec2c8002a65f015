#include "rewrite.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <map>

namespace steadyxr::layer {
namespace {

XrSwapchain fakeSwapchain(uintptr_t v) {
  return reinterpret_cast<XrSwapchain>(v);
}

XrCompositionLayerProjectionView view(XrSwapchain s, int32_t x, uint32_t arrayIndex, int32_t w = 320) {
  auto v = makeXr<XrCompositionLayerProjectionView>(XR_TYPE_COMPOSITION_LAYER_PROJECTION_VIEW);
  v.pose.orientation.w = 1.0f;
  v.fov = {-0.7f, 0.7f, 0.7f, -0.7f};
  v.subImage.swapchain = s;
  v.subImage.imageRect = {{x, 0}, {w, 240}};
  v.subImage.imageArrayIndex = arrayIndex;
  return v;
}

SwapchainFacts facts(uint32_t width, uint32_t arraySize, int64_t format = VK_FORMAT_R8G8B8A8_SRGB) {
  SwapchainFacts f;
  f.format = format;
  f.width = width;
  f.height = 240;
  f.arraySize = arraySize;
  f.hasReleasedImage = true;
  f.imagesKnown = true;
  return f;
}

struct Fixture {
  std::map<XrSwapchain, SwapchainFacts> known;
  SwapchainLookup lookup() const {
    return [this](XrSwapchain s) -> std::optional<SwapchainFacts> {
      auto it = known.find(s);
      if (it == known.end()) return std::nullopt;
      return it->second;
    };
  }
};

XrCompositionLayerProjection projection(const XrCompositionLayerProjectionView* views, uint32_t n) {
  auto p = makeXr<XrCompositionLayerProjection>(XR_TYPE_COMPOSITION_LAYER_PROJECTION);
  p.viewCount = n;
  p.views = views;
  return p;
}

TEST(PassThrough, AcceptsThreeSwapchainLayouts) {
  Fixture f;
  const XrSwapchain l = fakeSwapchain(1), r = fakeSwapchain(2), arr = fakeSwapchain(3),
                    sbs = fakeSwapchain(4);
  f.known[l] = facts(320, 1);
  f.known[r] = facts(320, 1);
  f.known[arr] = facts(320, 2);
  f.known[sbs] = facts(640, 1);
  const XrCompositionLayerProjectionView perEye[] = {view(l, 0, 0), view(r, 0, 0)};
  const XrCompositionLayerProjectionView array[] = {view(arr, 0, 0), view(arr, 0, 1)};
  const XrCompositionLayerProjectionView sideBySide[] = {view(sbs, 0, 0), view(sbs, 320, 0)};
  EXPECT_FALSE(checkProjection(projection(perEye, 2), f.lookup()));
  EXPECT_FALSE(checkProjection(projection(array, 2), f.lookup()));
  EXPECT_FALSE(checkProjection(projection(sideBySide, 2), f.lookup()));
}

TEST(PassThrough, Reasons) {
  Fixture f;
  const XrSwapchain s = fakeSwapchain(1);
  f.known[s] = facts(320, 1);
  const XrCompositionLayerProjectionView ok[] = {view(s, 0, 0), view(s, 0, 0)};
  EXPECT_EQ(checkProjection(projection(ok, 3), f.lookup()), PassReason::ViewCount);
  EXPECT_EQ(checkProjection(projection(nullptr, 2), f.lookup()), PassReason::ViewCount);

  const XrCompositionLayerProjectionView unknown[] = {view(fakeSwapchain(9), 0, 0), view(s, 0, 0)};
  EXPECT_EQ(checkProjection(projection(unknown, 2), f.lookup()), PassReason::UnknownSwapchain);

  const XrCompositionLayerProjectionView outside[] = {view(s, 10, 0), view(s, 0, 0)};
  EXPECT_EQ(checkProjection(projection(outside, 2), f.lookup()), PassReason::BadImageRect);
  const XrCompositionLayerProjectionView badLayer[] = {view(s, 0, 1), view(s, 0, 0)};
  EXPECT_EQ(checkProjection(projection(badLayer, 2), f.lookup()), PassReason::BadImageRect);

  XrCompositionLayerProjectionView lost[] = {view(s, 0, 0), view(s, 0, 0)};
  lost[1].pose.orientation.w = 0.0f;  // runtimes report all-zero poses when tracking is lost
  EXPECT_EQ(checkProjection(projection(lost, 2), f.lookup()), PassReason::MissingPose);
  XrCompositionLayerProjectionView badFov[] = {view(s, 0, 0), view(s, 0, 0)};
  badFov[0].fov.angleLeft = 0.9f;
  EXPECT_EQ(checkProjection(projection(badFov, 2), f.lookup()), PassReason::MissingPose);

  f.known[s].hasReleasedImage = false;
  EXPECT_EQ(checkProjection(projection(ok, 2), f.lookup()), PassReason::NoReleasedImage);
  f.known[s] = facts(320, 1, VK_FORMAT_R32G32B32A32_UINT);
  EXPECT_EQ(checkProjection(projection(ok, 2), f.lookup()), PassReason::UnsupportedFormat);
}

TEST(PassThrough, AlphaBlendedLayersFilteredOnlyWithPremultipliedColour) {
  Fixture f;
  const XrSwapchain s = fakeSwapchain(1);
  f.known[s] = facts(320, 1);
  const XrCompositionLayerProjectionView ok[] = {view(s, 0, 0), view(s, 0, 0)};
  XrCompositionLayerProjection p = projection(ok, 2);
  p.layerFlags = XR_COMPOSITION_LAYER_BLEND_TEXTURE_SOURCE_ALPHA_BIT;
  EXPECT_EQ(checkProjection(p, f.lookup()), std::nullopt);  // premultiplied: filtered, alpha carried
  p.layerFlags |= XR_COMPOSITION_LAYER_UNPREMULTIPLIED_ALPHA_BIT;
  EXPECT_EQ(checkProjection(p, f.lookup()), PassReason::UnpremultipliedAlpha);
  p.layerFlags = XR_COMPOSITION_LAYER_UNPREMULTIPLIED_ALPHA_BIT;  // alpha unused: opaque
  EXPECT_EQ(checkProjection(p, f.lookup()), std::nullopt);
}

TEST(Scan, InvalidFramesAreNeverRead) {
  EXPECT_EQ(scanFrame(nullptr, 16).problem, FrameProblem::NullInfo);
  auto info = makeXr<XrFrameEndInfo>(XR_TYPE_FRAME_END_INFO);
  info.layerCount = 1;  // the crash of issue 15: layers = NULL
  EXPECT_EQ(scanFrame(&info, 16).problem, FrameProblem::NullLayers);
  const XrCompositionLayerBaseHeader* one[] = {nullptr};
  info.layers = one;
  EXPECT_EQ(scanFrame(&info, 16).problem, FrameProblem::NullLayer);
  info.layerCount = 17;  // past the runtime's limit: not one entry is read
  EXPECT_EQ(scanFrame(&info, 16).problem, FrameProblem::TooManyLayers);
  info.layerCount = 0;
  info.type = XR_TYPE_FRAME_STATE;
  EXPECT_EQ(scanFrame(&info, 16).problem, FrameProblem::WrongType);
  info.type = XR_TYPE_FRAME_END_INFO;
  const FrameScan empty = scanFrame(&info, 16);
  EXPECT_TRUE(empty.ok());
  EXPECT_FALSE(empty.projection);
  auto quad = makeXr<XrCompositionLayerQuad>(XR_TYPE_COMPOSITION_LAYER_QUAD);
  const XrCompositionLayerProjection proj = projection(nullptr, 2);
  const XrCompositionLayerBaseHeader* layers[] = {
      reinterpret_cast<const XrCompositionLayerBaseHeader*>(&quad),
      reinterpret_cast<const XrCompositionLayerBaseHeader*>(&proj)};
  info.layers = layers;
  info.layerCount = 2;
  EXPECT_EQ(scanFrame(&info, 16).projection, 1u);
}

TEST(Scan, CyclicNextChainEndsTheWalk) {
  XrBaseInStructure a{static_cast<XrStructureType>(1000999000), nullptr};
  XrBaseInStructure b{static_cast<XrStructureType>(1000999001), &a};
  a.next = &b;  // a -> b -> a -> ...
  XrCompositionLayerProjectionView v = view(fakeSwapchain(1), 0, 0);
  v.next = &a;
  EXPECT_EQ(findDepthInfo(v), nullptr);
}

TEST(Rewrite, CopiesWithoutTouchingTheAppStructs) {
  const XrSwapchain app = fakeSwapchain(1), out = fakeSwapchain(100);
  auto depth = makeXr<XrCompositionLayerDepthInfoKHR>(XR_TYPE_COMPOSITION_LAYER_DEPTH_INFO_KHR);
  depth.subImage.swapchain = fakeSwapchain(7);
  XrCompositionLayerProjectionView views[] = {view(app, 0, 0, 640), view(app, 320, 0, 320)};
  views[0].subImage.imageRect.extent.width = 320;
  views[1].next = &depth;
  const XrCompositionLayerProjection proj = projection(views, 2);
  auto quad = makeXr<XrCompositionLayerQuad>(XR_TYPE_COMPOSITION_LAYER_QUAD);
  const XrCompositionLayerBaseHeader* layers[] = {
      reinterpret_cast<const XrCompositionLayerBaseHeader*>(&proj),
      reinterpret_cast<const XrCompositionLayerBaseHeader*>(&quad)};
  auto info = makeXr<XrFrameEndInfo>(XR_TYPE_FRAME_END_INFO);
  info.displayTime = 1234;
  info.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
  info.layerCount = 2;
  info.layers = layers;
  const XrCompositionLayerProjectionView before0 = views[0];

  FrameRewrite rw(info);
  rw.replaceProjection(0, {out, out});
  rw.replaceProjection(1, {out});  // a quad: ignored
  EXPECT_EQ(rw.replacedCount(), 1u);
  const XrFrameEndInfo& next = rw.info();
  EXPECT_EQ(next.displayTime, 1234);
  EXPECT_EQ(next.layerCount, 2u);
  EXPECT_EQ(next.layers[1], layers[1]);  // other layer types pass through as the same pointer
  ASSERT_NE(next.layers[0], layers[0]);
  const auto* copy = reinterpret_cast<const XrCompositionLayerProjection*>(next.layers[0]);
  ASSERT_EQ(copy->viewCount, 2u);
  EXPECT_NE(copy->views, views);
  for (uint32_t i = 0; i < 2; ++i) {
    EXPECT_EQ(copy->views[i].subImage.swapchain, out);
    EXPECT_EQ(copy->views[i].subImage.imageRect.offset.x, views[i].subImage.imageRect.offset.x);
    EXPECT_EQ(copy->views[i].subImage.imageArrayIndex, views[i].subImage.imageArrayIndex);
  }
  EXPECT_EQ(copy->views[1].next, &depth);  // depth stays chained (the app's depth swapchain)
  EXPECT_EQ(findDepthInfo(copy->views[1]), &depth);
  EXPECT_EQ(findDepthInfo(copy->views[0]), nullptr);
  // The app's structs are unchanged.
  EXPECT_EQ(views[0].subImage.swapchain, app);
  EXPECT_EQ(std::memcmp(&views[0], &before0, sizeof before0), 0);
  EXPECT_EQ(info.layers, layers);
}

TEST(Rewrite, UnjitteredFov) {
  const XrSwapchain app = fakeSwapchain(1), out = fakeSwapchain(2);
  const XrCompositionLayerProjectionView views[] = {view(app, 0, 0), view(app, 0, 0)};
  const XrCompositionLayerProjection proj = projection(views, 2);
  const XrCompositionLayerBaseHeader* layers[] = {
      reinterpret_cast<const XrCompositionLayerBaseHeader*>(&proj)};
  auto info = makeXr<XrFrameEndInfo>(XR_TYPE_FRAME_END_INFO);
  info.layerCount = 1;
  info.layers = layers;
  FrameRewrite rw(info);
  const std::vector<XrFovf> fovs{{-0.5f, 0.5f, 0.5f, -0.5f}, {-0.6f, 0.6f, 0.6f, -0.6f}};
  rw.replaceProjection(0, {out, out}, &fovs);
  const auto* copy = reinterpret_cast<const XrCompositionLayerProjection*>(rw.info().layers[0]);
  EXPECT_FLOAT_EQ(copy->views[1].fov.angleLeft, -0.6f);
  EXPECT_FLOAT_EQ(views[1].fov.angleLeft, -0.7f);
}

TEST(Jitter, HaltonAndFovShift) {
  EXPECT_FLOAT_EQ(halton(1, 2), 0.5f);
  EXPECT_FLOAT_EQ(halton(2, 2), 0.25f);
  EXPECT_FLOAT_EQ(halton(3, 2), 0.75f);
  EXPECT_NEAR(halton(1, 3), 1.0f / 3.0f, 1e-6f);
  EXPECT_NEAR(halton(2, 3), 2.0f / 3.0f, 1e-6f);
  const XrFovf fov{-0.7f, 0.6f, 0.5f, -0.8f};
  const XrFovf same = jitterFov(fov, 0.0f, 0.0f, 320, 240);
  EXPECT_NEAR(same.angleLeft, fov.angleLeft, 1e-6f);
  EXPECT_NEAR(same.angleUp, fov.angleUp, 1e-6f);
  // Half a pixel right and a quarter pixel down, measured in tangent space.
  const XrFovf j = jitterFov(fov, 0.5f, 0.25f, 320, 240);
  const float pxX = (std::tan(fov.angleRight) - std::tan(fov.angleLeft)) / 320.0f;
  const float pxY = (std::tan(fov.angleUp) - std::tan(fov.angleDown)) / 240.0f;
  EXPECT_NEAR(std::tan(j.angleLeft) - std::tan(fov.angleLeft), 0.5f * pxX, 1e-5f);
  EXPECT_NEAR(std::tan(j.angleRight) - std::tan(fov.angleRight), 0.5f * pxX, 1e-5f);
  EXPECT_NEAR(std::tan(fov.angleUp) - std::tan(j.angleUp), 0.25f * pxY, 1e-5f);
  EXPECT_NEAR(std::tan(fov.angleDown) - std::tan(j.angleDown), 0.25f * pxY, 1e-5f);
  EXPECT_TRUE(isValidFov(j));
}

TEST(Swapchains, UsageAndOutputInfo) {
  EXPECT_EQ(appSwapchainUsage(XR_SWAPCHAIN_USAGE_COLOR_ATTACHMENT_BIT),
            XR_SWAPCHAIN_USAGE_COLOR_ATTACHMENT_BIT | XR_SWAPCHAIN_USAGE_SAMPLED_BIT);
  auto app = makeXr<XrSwapchainCreateInfo>(XR_TYPE_SWAPCHAIN_CREATE_INFO);
  app.format = VK_FORMAT_R8G8B8A8_SRGB;
  app.width = 640;
  app.height = 480;
  app.arraySize = 2;
  app.sampleCount = 1;
  app.mipCount = 1;
  app.faceCount = 1;
  app.createFlags = XR_SWAPCHAIN_CREATE_STATIC_IMAGE_BIT;
  EXPECT_TRUE(isReadableSwapchain(app));
  XrSwapchainCreateInfo msaa = app;
  msaa.sampleCount = 4;
  EXPECT_FALSE(isReadableSwapchain(msaa));
  XrSwapchainCreateInfo prot = app;
  prot.createFlags |= XR_SWAPCHAIN_CREATE_PROTECTED_CONTENT_BIT;
  EXPECT_FALSE(isReadableSwapchain(prot));
  const XrSwapchainCreateInfo srgb = outputSwapchainInfo(app, false);
  EXPECT_EQ(srgb.format, app.format);
  EXPECT_EQ(srgb.width, 640u);
  EXPECT_EQ(srgb.arraySize, 2u);
  EXPECT_EQ(srgb.createFlags, 0u);
  EXPECT_TRUE(srgb.usageFlags & XR_SWAPCHAIN_USAGE_TRANSFER_DST_BIT);
  EXPECT_FALSE(srgb.usageFlags & XR_SWAPCHAIN_USAGE_UNORDERED_ACCESS_BIT);
  const XrSwapchainCreateInfo srgbMutable = outputSwapchainInfo(app, true);
  EXPECT_TRUE(srgbMutable.usageFlags & XR_SWAPCHAIN_USAGE_MUTABLE_FORMAT_BIT);
  EXPECT_TRUE(srgbMutable.usageFlags & XR_SWAPCHAIN_USAGE_UNORDERED_ACCESS_BIT);
  app.format = VK_FORMAT_R16G16B16A16_SFLOAT;
  EXPECT_TRUE(outputSwapchainInfo(app, false).usageFlags & XR_SWAPCHAIN_USAGE_UNORDERED_ACCESS_BIT);
  EXPECT_EQ(vulkanUsage(XR_SWAPCHAIN_USAGE_UNORDERED_ACCESS_BIT | XR_SWAPCHAIN_USAGE_SAMPLED_BIT),
            static_cast<VkImageUsageFlags>(VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT));
}

}  // namespace
}  // namespace steadyxr::layer
