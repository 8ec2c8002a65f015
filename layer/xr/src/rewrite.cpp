#include "rewrite.h"

#include <algorithm>
#include <cmath>

namespace steadyxr::layer {

std::string_view toString(PassReason r) {
  switch (r) {
    case PassReason::Disabled:
      return "disabled";
    case PassReason::NotVulkan:
      return "not_vulkan";
    case PassReason::NoProjectionLayer:
      return "no_projection_layer";
    case PassReason::ViewCount:
      return "view_count";
    case PassReason::UnknownSwapchain:
      return "unknown_swapchain";
    case PassReason::NoReleasedImage:
      return "no_released_image";
    case PassReason::UnsupportedFormat:
      return "unsupported_format";
    case PassReason::BadImageRect:
      return "bad_image_rect";
    case PassReason::MissingPose:
      return "missing_pose";
    case PassReason::OutputSwapchain:
      return "output_swapchain";
    case PassReason::XrError:
      return "openxr_error";
    case PassReason::FilterError:
      return "filter_error";
    case PassReason::Compiling:
      return "compiling";
    case PassReason::InvalidFrame:
      return "invalid_frame";
    case PassReason::UnpremultipliedAlpha:
      return "unpremultiplied_alpha";
    case PassReason::RuntimeRejected:
      return "runtime_rejected";
    case PassReason::Count:
      break;
  }
  return "unknown";
}

std::string_view toString(FrameProblem p) {
  switch (p) {
    case FrameProblem::None:
      return "none";
    case FrameProblem::NullInfo:
      return "null XrFrameEndInfo";
    case FrameProblem::WrongType:
      return "XrFrameEndInfo with a wrong type";
    case FrameProblem::TooManyLayers:
      return "layerCount above the runtime's maxLayerCount";
    case FrameProblem::NullLayers:
      return "layerCount > 0 with layers = NULL";
    case FrameProblem::NullLayer:
      return "a NULL entry in layers";
  }
  return "unknown";
}

FrameScan scanFrame(const XrFrameEndInfo* info, uint32_t maxLayerCount) {
  FrameScan scan;
  if (info == nullptr) {
    scan.problem = FrameProblem::NullInfo;
  } else if (info->type != XR_TYPE_FRAME_END_INFO) {
    scan.problem = FrameProblem::WrongType;
  } else if (info->layerCount > std::min(maxLayerCount, kMaxLayerLimit)) {
    scan.problem = FrameProblem::TooManyLayers;
  } else if (info->layerCount > 0 && info->layers == nullptr) {
    scan.problem = FrameProblem::NullLayers;
  }
  for (uint32_t i = 0; scan.ok() && i < info->layerCount; ++i) {
    const XrCompositionLayerBaseHeader* l = info->layers[i];
    if (l == nullptr) {
      scan.problem = FrameProblem::NullLayer;
    } else if (!scan.projection && l->type == XR_TYPE_COMPOSITION_LAYER_PROJECTION) {
      scan.projection = i;
    }
  }
  if (!scan.ok()) scan.projection.reset();
  return scan;
}

bool isFilterableColorFormat(int64_t f) {
  switch (static_cast<VkFormat>(f)) {
    case VK_FORMAT_R8G8B8A8_UNORM:
    case VK_FORMAT_R8G8B8A8_SRGB:
    case VK_FORMAT_B8G8R8A8_UNORM:
    case VK_FORMAT_B8G8R8A8_SRGB:
    case VK_FORMAT_A2B10G10R10_UNORM_PACK32:
    case VK_FORMAT_R16G16B16A16_SFLOAT:
      return true;
    default:
      return false;
  }
}

bool isSrgbFormat(int64_t f) {
  return f == VK_FORMAT_R8G8B8A8_SRGB || f == VK_FORMAT_B8G8R8A8_SRGB;
}

bool isDepthFormat(int64_t f) {
  switch (static_cast<VkFormat>(f)) {
    case VK_FORMAT_D16_UNORM:
    case VK_FORMAT_D32_SFLOAT:
    case VK_FORMAT_D24_UNORM_S8_UINT:
    case VK_FORMAT_D32_SFLOAT_S8_UINT:
    case VK_FORMAT_X8_D24_UNORM_PACK32:
      return true;
    default:
      return false;
  }
}

bool isValidPose(const XrPosef& p) {
  const XrQuaternionf& q = p.orientation;
  const float n = q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w;
  const bool finite = std::isfinite(n) && std::isfinite(p.position.x) && std::isfinite(p.position.y) &&
                      std::isfinite(p.position.z);
  // Runtimes hand out all-zero poses when tracking is lost; OpenXR requires unit quaternions.
  return finite && std::fabs(n - 1.0f) < 0.01f;
}

bool isValidFov(const XrFovf& f) {
  const bool finite = std::isfinite(f.angleLeft) && std::isfinite(f.angleRight) && std::isfinite(f.angleUp) &&
                      std::isfinite(f.angleDown);
  return finite && f.angleRight > f.angleLeft && f.angleUp > f.angleDown && f.angleLeft > -1.57f &&
         f.angleRight < 1.57f && f.angleDown > -1.57f && f.angleUp < 1.57f;
}

std::optional<PassReason> checkProjection(const XrCompositionLayerProjection& layer,
                                          const SwapchainLookup& lookup) {
  if (layer.viewCount < 1 || layer.viewCount > 2 || layer.views == nullptr) return PassReason::ViewCount;
  // Straight (unpremultiplied) colour under alpha 0 is whatever the app left there; every
  // neighbourhood or reprojection filter would pull it into the visible edge pixels.
  if ((layer.layerFlags & XR_COMPOSITION_LAYER_BLEND_TEXTURE_SOURCE_ALPHA_BIT) &&
      (layer.layerFlags & XR_COMPOSITION_LAYER_UNPREMULTIPLIED_ALPHA_BIT))
    return PassReason::UnpremultipliedAlpha;
  for (uint32_t i = 0; i < layer.viewCount; ++i) {
    const XrCompositionLayerProjectionView& v = layer.views[i];
    const std::optional<SwapchainFacts> facts = lookup(v.subImage.swapchain);
    if (!facts || !facts->imagesKnown) return PassReason::UnknownSwapchain;
    if (!facts->hasReleasedImage) return PassReason::NoReleasedImage;
    if (!isFilterableColorFormat(facts->format)) return PassReason::UnsupportedFormat;
    const XrRect2Di& r = v.subImage.imageRect;
    if (r.offset.x < 0 || r.offset.y < 0 || r.extent.width <= 0 || r.extent.height <= 0 ||
        static_cast<int64_t>(r.offset.x) + r.extent.width > facts->width ||
        static_cast<int64_t>(r.offset.y) + r.extent.height > facts->height ||
        v.subImage.imageArrayIndex >= facts->arraySize) {
      return PassReason::BadImageRect;
    }
    if (!isValidPose(v.pose) || !isValidFov(v.fov)) return PassReason::MissingPose;
  }
  return std::nullopt;
}

const XrCompositionLayerDepthInfoKHR* findDepthInfo(const XrCompositionLayerProjectionView& view) {
  uint32_t walked = 0;
  for (auto* h = static_cast<const XrBaseInStructure*>(view.next); h != nullptr && walked < kMaxNextChain;
       h = h->next, ++walked) {
    if (h->type == XR_TYPE_COMPOSITION_LAYER_DEPTH_INFO_KHR) {
      return reinterpret_cast<const XrCompositionLayerDepthInfoKHR*>(h);
    }
  }
  return nullptr;
}

bool isReadableSwapchain(const XrSwapchainCreateInfo& info) {
  return info.sampleCount <= 1 && info.faceCount <= 1 &&
         (info.createFlags & XR_SWAPCHAIN_CREATE_PROTECTED_CONTENT_BIT) == 0;
}

XrSwapchainUsageFlags appSwapchainUsage(XrSwapchainUsageFlags requested) {
  return requested | XR_SWAPCHAIN_USAGE_SAMPLED_BIT;
}

XrSwapchainCreateInfo outputSwapchainInfo(const XrSwapchainCreateInfo& app, bool mutableFormatSupported) {
  auto out = makeXr<XrSwapchainCreateInfo>(XR_TYPE_SWAPCHAIN_CREATE_INFO);
  out.createFlags = 0;  // never static: the layer writes every frame
  out.format = app.format;
  out.sampleCount = 1;
  out.width = app.width;
  out.height = app.height;
  out.faceCount = 1;
  out.arraySize = app.arraySize;
  out.mipCount = 1;
  out.usageFlags = XR_SWAPCHAIN_USAGE_COLOR_ATTACHMENT_BIT | XR_SWAPCHAIN_USAGE_TRANSFER_DST_BIT |
                   XR_SWAPCHAIN_USAGE_SAMPLED_BIT;
  // Storage writes to sRGB images need a UNORM view (mutable format); without it the core
  // writes an intermediate image and copies.
  if (!isSrgbFormat(app.format)) {
    out.usageFlags |= XR_SWAPCHAIN_USAGE_UNORDERED_ACCESS_BIT;
  } else if (mutableFormatSupported) {
    out.usageFlags |= XR_SWAPCHAIN_USAGE_UNORDERED_ACCESS_BIT | XR_SWAPCHAIN_USAGE_MUTABLE_FORMAT_BIT;
  }
  return out;
}

VkImageUsageFlags vulkanUsage(XrSwapchainUsageFlags u) {
  VkImageUsageFlags v = 0;
  if (u & XR_SWAPCHAIN_USAGE_COLOR_ATTACHMENT_BIT) v |= VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT;
  if (u & XR_SWAPCHAIN_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT) v |= VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT;
  if (u & XR_SWAPCHAIN_USAGE_UNORDERED_ACCESS_BIT) v |= VK_IMAGE_USAGE_STORAGE_BIT;
  if (u & XR_SWAPCHAIN_USAGE_TRANSFER_SRC_BIT) v |= VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  if (u & XR_SWAPCHAIN_USAGE_TRANSFER_DST_BIT) v |= VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  if (u & XR_SWAPCHAIN_USAGE_SAMPLED_BIT) v |= VK_IMAGE_USAGE_SAMPLED_BIT;
  return v;
}

XrFovf jitterFov(const XrFovf& fov, float dxPx, float dyPx, uint32_t width, uint32_t height) {
  const core::Fov j =
      core::jitterFov({fov.angleLeft, fov.angleRight, fov.angleUp, fov.angleDown}, dxPx, dyPx, width, height);
  return {j.angleLeft, j.angleRight, j.angleUp, j.angleDown};
}

uint32_t JitterTracker::apply(XrFovf* fovs, const VkExtent2D* sizes, uint32_t count) {
  if (fovs == nullptr || sizes == nullptr || count == 0 || count > kMaxViews) return 0;
  const glm::vec2 offset = core::haltonJitterPx(jitterCalls_++);
  Call& call = ring_[next_];
  call = {};
  call.dxPx = offset.x;
  call.dyPx = offset.y;
  uint32_t jittered = 0;
  for (uint32_t i = 0; i < count; ++i) {
    if (sizes[i].width == 0 || sizes[i].height == 0 || !isValidFov(fovs[i])) continue;
    const XrFovf j = jitterFov(fovs[i], call.dxPx, call.dyPx, sizes[i].width, sizes[i].height);
    if (!isValidFov(j)) continue;  // a fov at the edge of the valid range: leave it as is
    call.views[i] = {fovs[i], j, sizes[i], true};
    fovs[i] = j;
    ++jittered;
  }
  next_ = (next_ + 1) % kCalls;
  count_ = std::min(count_ + 1, kCalls);
  return jittered;
}

ViewUnjitter JitterTracker::find(uint32_t view, const XrFovf& submitted, VkExtent2D size) const {
  ViewUnjitter out;
  out.fov = submitted;
  if (view >= kMaxViews) return out;
  const auto near = [](float a, float b) { return std::fabs(a - b) <= kMatchRad; };
  for (uint32_t k = 1; k <= count_; ++k) {  // newest first
    const Call& call = ring_[(next_ + kCalls - k) % kCalls];
    const View& v = call.views[view];
    if (!v.valid || !near(v.jittered.angleLeft, submitted.angleLeft) ||
        !near(v.jittered.angleRight, submitted.angleRight) || !near(v.jittered.angleUp, submitted.angleUp) ||
        !near(v.jittered.angleDown, submitted.angleDown)) {
      continue;
    }
    out.fov = v.original;
    // The shift is fixed in tangent space; in pixels it scales with the submitted image size.
    const float sx = size.width ? static_cast<float>(size.width) / static_cast<float>(v.size.width) : 1.0f;
    const float sy = size.height ? static_cast<float>(size.height) / static_cast<float>(v.size.height) : 1.0f;
    out.jitterPx[0] = call.dxPx * sx;
    out.jitterPx[1] = call.dyPx * sy;
    out.matched = true;
    return out;
  }
  return out;
}

FrameRewrite::FrameRewrite(const XrFrameEndInfo& app) : info_(app) {
  if (app.layers == nullptr || app.layerCount == 0 || app.layerCount > kMaxLayerLimit) return;
  layers_.assign(app.layers, app.layers + app.layerCount);
  info_.layers = layers_.data();
}

void FrameRewrite::replaceProjection(uint32_t index, const std::vector<XrSwapchain>& swapchains,
                                     const std::vector<XrFovf>* fovs) {
  if (index >= layers_.size() || layers_[index] == nullptr ||
      layers_[index]->type != XR_TYPE_COMPOSITION_LAYER_PROJECTION)
    return;
  const auto& src = *reinterpret_cast<const XrCompositionLayerProjection*>(layers_[index]);
  // The views are read only as far as checkProjection allows (1 or 2, non-null).
  if (src.views == nullptr || src.viewCount < 1 || src.viewCount > 2 || swapchains.size() != src.viewCount)
    return;
  std::vector<XrCompositionLayerProjectionView>& views =
      views_.emplace_back(src.views, src.views + src.viewCount);
  for (uint32_t i = 0; i < src.viewCount; ++i) {
    views[i].subImage.swapchain = swapchains[i];
    if (fovs && fovs->size() == src.viewCount) views[i].fov = (*fovs)[i];
  }
  XrCompositionLayerProjection& copy = projections_.emplace_back(src);
  copy.views = views.data();
  layers_[index] = reinterpret_cast<const XrCompositionLayerBaseHeader*>(&copy);
  ++replaced_;
}

}  // namespace steadyxr::layer
