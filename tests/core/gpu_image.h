// Test helpers: device images with upload/download through a staging buffer (real Vulkan).
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <glm/vec4.hpp>
#include <memory>
#include <string>
#include <vector>

#include "steadyxr/core/frame.h"
#include "steadyxr/core/vulkan_context.h"

namespace steadyxr::test {

// IEC 61966-2-1 (sRGB), written from the standard, for every test that must know what an SRGB
// image stores: the encoded value (0..1, unrounded) of linear `linear`, clamped to [0, 1] first,
// and the linear value of encoded `encoded`.
inline double srgbEncode(double linear) {
  linear = std::clamp(linear, 0.0, 1.0);
  return linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
}
inline double srgbDecode(double encoded) {
  return encoded <= 0.04045 ? encoded / 12.92 : std::pow((encoded + 0.055) / 1.055, 2.4);
}

// RGBA float pixels, row-major, row 0 at the top.
struct HostImage {
  uint32_t width = 0, height = 0;
  std::vector<glm::vec4> px;
  HostImage() = default;
  HostImage(uint32_t w, uint32_t h, glm::vec4 fill = glm::vec4(0, 0, 0, 1))
      : width(w), height(h), px(w * h, fill) {}
  glm::vec4& at(uint32_t x, uint32_t y) { return px[y * width + x]; }
  const glm::vec4& at(uint32_t x, uint32_t y) const { return px[y * width + x]; }
};

class GpuImage {
 public:
  // Colour images hold linear values on the host side: SRGB formats are encoded on upload and
  // decoded on download. Depth images (D32_SFLOAT) carry the depth value in .r.
  GpuImage(core::VulkanContext& ctx, VkFormat format, uint32_t width, uint32_t height, uint32_t layers,
           VkImageUsageFlags usage, bool mutableFormat = false);
  ~GpuImage();
  GpuImage(const GpuImage&) = delete;
  GpuImage& operator=(const GpuImage&) = delete;

  // Leaves the image in `layout`.
  void upload(const HostImage& img, uint32_t layer, VkImageLayout layout, uint32_t x0 = 0, uint32_t y0 = 0);
  // Reads a region of the image, which must be in `layout`; leaves it there.
  HostImage download(uint32_t layer, VkImageLayout layout, uint32_t x0, uint32_t y0, uint32_t w, uint32_t h);
  HostImage download(uint32_t layer, VkImageLayout layout) {
    return download(layer, layout, 0, 0, width_, height_);
  }
  // Transitions the whole image (all layers) from `from` to `to` and waits.
  void transition(VkImageLayout from, VkImageLayout to);

  core::ImageRef ref(uint32_t layer, VkImageLayout layout, VkRect2D rect = {}) const;
  VkImage image() const { return image_; }
  VkFormat format() const { return format_; }

 private:
  void runOnce(const std::function<void(VkCommandBuffer)>& record);
  core::VulkanContext& ctx_;
  VkFormat format_;
  uint32_t width_, height_, layers_;
  VkImageUsageFlags usage_;
  bool mutable_;
  VkImage image_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
};

}  // namespace steadyxr::test
