// Which Vulkan formats, layouts and rects the filter accepts, and how it treats each.
#pragma once

#include <algorithm>
#include <cstdint>

#include <vulkan/vulkan.h>

#include "steadyxr/core/frame.h"

namespace steadyxr::core::detail {

inline bool isSrgb(VkFormat f) {
  return f == VK_FORMAT_R8G8B8A8_SRGB || f == VK_FORMAT_B8G8R8A8_SRGB;
}
inline bool isBgra(VkFormat f) {
  return f == VK_FORMAT_B8G8R8A8_UNORM || f == VK_FORMAT_B8G8R8A8_SRGB;
}
// 8-bit UNORM/sRGB texels decode to [0, 1]: never NaN or Inf, so the shader need not sanitise them.
inline bool isUnorm8(VkFormat f) {
  return f == VK_FORMAT_R8G8B8A8_UNORM || f == VK_FORMAT_R8G8B8A8_SRGB || f == VK_FORMAT_B8G8R8A8_UNORM ||
         f == VK_FORMAT_B8G8R8A8_SRGB;
}
inline bool isOutputFormat(VkFormat f) {
  return f == VK_FORMAT_R8G8B8A8_UNORM || f == VK_FORMAT_R8G8B8A8_SRGB || f == VK_FORMAT_B8G8R8A8_UNORM ||
         f == VK_FORMAT_B8G8R8A8_SRGB || f == VK_FORMAT_R16G16B16A16_SFLOAT;
}
inline bool isDepthFormat(VkFormat f) {
  return f == VK_FORMAT_D16_UNORM || f == VK_FORMAT_D32_SFLOAT || f == VK_FORMAT_D24_UNORM_S8_UINT ||
         f == VK_FORMAT_D32_SFLOAT_S8_UINT || f == VK_FORMAT_X8_D24_UNORM_PACK32 ||
         f == VK_FORMAT_D16_UNORM_S8_UINT;
}
inline bool hasStencil(VkFormat f) {
  return f == VK_FORMAT_D24_UNORM_S8_UINT || f == VK_FORMAT_D32_SFLOAT_S8_UINT ||
         f == VK_FORMAT_D16_UNORM_S8_UINT;
}

// The layout an app image is sampled in: its own when a shader may read it there.
inline VkImageLayout sampledLayout(VkImageLayout l, bool depth) {
  if (l == VK_IMAGE_LAYOUT_GENERAL || l == VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL) return l;
  if (depth && l == VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL) return l;
  return VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
}

inline bool rectInside(const ImageRef& r) {
  return r.rect.extent.width > 0 && r.rect.extent.height > 0 && r.rect.offset.x >= 0 &&
         r.rect.offset.y >= 0 &&
         static_cast<uint64_t>(r.rect.offset.x) + r.rect.extent.width <= r.extent.width &&
         static_cast<uint64_t>(r.rect.offset.y) + r.rect.extent.height <= r.extent.height &&
         r.arrayLayer < std::max(r.arrayLayerCount, 1u);
}

inline bool sameExtent(VkExtent2D a, VkExtent2D b) {
  return a.width == b.width && a.height == b.height;
}

}  // namespace steadyxr::core::detail
