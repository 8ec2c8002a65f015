// The benchmark's eye images (bench_input.h).
#include "bench_input.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <glm/gtc/packing.hpp>

#include "steadyxr/core/vk_handle.h"

namespace steadyxr::bench {

namespace {
constexpr double kPi = 3.14159265358979323846;
// The rings' frequencies per channel, relative to green's: chroma in the picture.
constexpr glm::vec3 kChannelFrequency(1.07f, 1.0f, 0.93f);

// IEC 61966-2-1's encoding of a linear value in [0, 1].
float srgbEncode(float linear) {
  linear = std::clamp(linear, 0.0f, 1.0f);
  return linear <= 0.0031308f ? 12.92f * linear : 1.055f * std::pow(linear, 1.0f / 2.4f) - 0.055f;
}
uint8_t toCode(float encoded) {
  return static_cast<uint8_t>(std::lround(std::clamp(encoded, 0.0f, 1.0f) * 255.0f));
}
}  // namespace

glm::vec3 pixelDirection(VkExtent2D size, const core::Fov& fov, const glm::quat& orientation, float x,
                         float y) {
  const float l = std::tan(fov.angleLeft), r = std::tan(fov.angleRight);
  const float u = std::tan(fov.angleUp), d = std::tan(fov.angleDown);
  const glm::vec3 view(l + (x + 0.5f) / float(size.width) * (r - l),
                       u - (y + 0.5f) / float(size.height) * (u - d), -1.0f);
  return glm::normalize(orientation) * view;
}

std::vector<glm::vec4> renderZonePlate(VkExtent2D size, const core::Fov& fov, const glm::quat& orientation) {
  // Phase pi k rho^2 at rho from the axis (the plane's coordinates at distance 1): k rho cycles per unit,
  // one cycle per two pixels (Nyquist) at half the view's mean half-width.
  const float unitsPerPixel = (std::tan(fov.angleRight) - std::tan(fov.angleLeft)) / float(size.width);
  const float halfWidth = 0.25f * (std::tan(fov.angleRight) - std::tan(fov.angleLeft) +
                                   std::tan(fov.angleUp) - std::tan(fov.angleDown));
  const float k = 0.5f / unitsPerPixel / (0.5f * halfWidth);
  std::vector<glm::vec4> pixels(size_t(size.width) * size.height);
  for (uint32_t y = 0; y < size.height; ++y)
    for (uint32_t x = 0; x < size.width; ++x) {
      const glm::vec3 w = pixelDirection(size, fov, orientation, float(x), float(y));
      const double along = std::max(-double(w.z), 1e-3);  // behind the viewer: the plane's far rim
      const double rho2 = (double(w.x) * w.x + double(w.y) * w.y) / (along * along);
      glm::vec4 c(1.0f);
      for (int ch = 0; ch < 3; ++ch)  // in double: the phase reaches thousands of radians at the edge
        c[ch] = float(0.5 + 0.5 * std::cos(kPi * double(k) * rho2 * double(kChannelFrequency[ch])));
      pixels[size_t(y) * size.width + x] = c;
    }
  return pixels;
}

bool fillImage(core::VulkanContext& ctx, VkImage image, const std::function<void(VkCommandBuffer)>& record,
               std::string* error, VkImageAspectFlags aspect) {
  const VkDevice device = ctx.device();
  VkCommandPoolCreateInfo cpci{};
  cpci.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
  cpci.queueFamilyIndex = ctx.queueFamilyIndex();
  VkCommandPool pool = VK_NULL_HANDLE;
  if (vkCreateCommandPool(device, &cpci, nullptr, &pool) != VK_SUCCESS) return *error = "command pool", false;
  const core::Unique<VkCommandPool> poolOwner(device, pool);  // frees its command buffer too
  VkCommandBufferAllocateInfo cbai{};
  cbai.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
  cbai.commandPool = pool;
  cbai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  cbai.commandBufferCount = 1;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  if (vkAllocateCommandBuffers(device, &cbai, &cmd) != VK_SUCCESS) return *error = "command buffer", false;
  VkCommandBufferBeginInfo bi{};
  bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  vkBeginCommandBuffer(cmd, &bi);
  VkImageMemoryBarrier b{};
  b.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
  b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.image = image;
  b.subresourceRange = {aspect, 0, 1, 0, 1};
  b.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  b.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
  b.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr,
                       0, nullptr, 1, &b);
  record(cmd);
  b.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
  b.newLayout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
  b.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  b.dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 0,
                       nullptr, 0, nullptr, 1, &b);
  vkEndCommandBuffer(cmd);
  VkSubmitInfo si{};
  si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cmd;
  if (vkQueueSubmit(ctx.queue(), 1, &si, VK_NULL_HANDLE) != VK_SUCCESS) return *error = "submit", false;
  vkQueueWaitIdle(ctx.queue());
  return true;
}

bool clearImage(core::VulkanContext& ctx, VkImage image, const glm::vec4& colour, std::string* error) {
  return fillImage(
      ctx, image,
      [&](VkCommandBuffer cmd) {
        const VkClearColorValue value{{colour.r, colour.g, colour.b, colour.a}};
        const VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
        vkCmdClearColorImage(cmd, image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &value, 1, &range);
      },
      error);
}

bool clearDepthImage(core::VulkanContext& ctx, VkImage image, float depth, std::string* error) {
  return fillImage(
      ctx, image,
      [&](VkCommandBuffer cmd) {
        const VkClearDepthStencilValue value{depth, 0};
        const VkImageSubresourceRange range{VK_IMAGE_ASPECT_DEPTH_BIT, 0, 1, 0, 1};
        vkCmdClearDepthStencilImage(cmd, image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &value, 1, &range);
      },
      error, VK_IMAGE_ASPECT_DEPTH_BIT);
}

bool uploadImage(core::VulkanContext& ctx, VkImage image, VkFormat format, VkExtent2D size,
                 const std::vector<glm::vec4>& pixels, std::string* error) {
  const VkDevice device = ctx.device();
  const bool half = format == VK_FORMAT_R16G16B16A16_SFLOAT;
  const bool srgb = format == VK_FORMAT_R8G8B8A8_SRGB;
  if (!half && !srgb && format != VK_FORMAT_R8G8B8A8_UNORM) return *error = "unsupported input format", false;
  if (pixels.size() != size_t(size.width) * size.height) return *error = "pixel count", false;
  const VkDeviceSize bytes = VkDeviceSize(pixels.size()) * (half ? 8 : 4);
  VkBufferCreateInfo bci{};
  bci.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
  bci.size = bytes;
  bci.usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
  VkBuffer buffer = VK_NULL_HANDLE;
  if (vkCreateBuffer(device, &bci, nullptr, &buffer) != VK_SUCCESS) return *error = "staging buffer", false;
  const core::Unique<VkBuffer> bufferOwner(device, buffer);
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(device, buffer, &req);
  VkMemoryAllocateInfo mai{};
  mai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
  mai.allocationSize = req.size;
  mai.memoryTypeIndex = ctx.findMemoryType(
      req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
  VkDeviceMemory memory = VK_NULL_HANDLE;
  if (mai.memoryTypeIndex == UINT32_MAX || vkAllocateMemory(device, &mai, nullptr, &memory) != VK_SUCCESS)
    return *error = "staging memory", false;
  const core::Unique<VkDeviceMemory> memoryOwner(device, memory);
  vkBindBufferMemory(device, buffer, memory, 0);
  void* mapped = nullptr;
  if (vkMapMemory(device, memory, 0, bytes, 0, &mapped) != VK_SUCCESS) return *error = "map", false;
  for (size_t i = 0; i < pixels.size(); ++i) {
    const glm::vec4& p = pixels[i];
    if (half) {
      const uint64_t packed = glm::packHalf4x16(p);
      std::memcpy(static_cast<char*>(mapped) + 8 * i, &packed, 8);
    } else {
      const uint8_t px[4] = {toCode(srgb ? srgbEncode(p.r) : p.r), toCode(srgb ? srgbEncode(p.g) : p.g),
                             toCode(srgb ? srgbEncode(p.b) : p.b), toCode(p.a)};
      std::memcpy(static_cast<char*>(mapped) + 4 * i, px, 4);
    }
  }
  vkUnmapMemory(device, memory);

  return fillImage(
      ctx, image,
      [&](VkCommandBuffer cmd) {
        VkBufferImageCopy region{};
        region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
        region.imageExtent = {size.width, size.height, 1};
        vkCmdCopyBufferToImage(cmd, buffer, image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
      },
      error);
}

}  // namespace steadyxr::bench
