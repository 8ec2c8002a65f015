#include "dump.h"

#include "rewrite.h"
#include "steadyxr/core/vk_handle.h"

#include <atomic>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <vector>

#include <unistd.h>

#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_WRITE_STATIC
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#include <stb/stb_image_write.h>
#pragma GCC diagnostic pop

namespace steadyxr::layer {
namespace {

constexpr uint64_t kFenceTimeoutNs = 2'000'000'000;  // a dump may stall, never hang

VkImageAspectFlags colorAspect() {
  return VK_IMAGE_ASPECT_COLOR_BIT;
}

}  // namespace

ImageDumper::ImageDumper(std::string dir, uint32_t maxFrames) : dir_(std::move(dir)), maxFrames_(maxFrames) {
  static std::atomic<uint32_t> dumpers{0};
  // Appended piece by piece: GCC 12 at -O3 warns (-Wrestrict, a false positive) on "p" + std::string&&.
  tag_ = 'p';
  tag_ += std::to_string(static_cast<long>(getpid()));
  tag_ += 's';
  tag_ += std::to_string(++dumpers);
}

void ImageDumper::dump(core::VulkanContext& vk, const core::StereoFrame& in, const core::StereoOutput& out,
                       Logger& log) {
  if (!wants()) return;
  if (!folderChecked_) {
    folderChecked_ = true;
    std::error_code ec;
    std::filesystem::create_directories(dir_, ec);
    if (!std::filesystem::is_directory(dir_, ec)) {
      disabled_ = true;
      log.log(LogLevel::Warn, "dump: cannot create folder '" + dir_ + "'" +
                                  (ec ? " (" + ec.message() + ")" : "") + ": dumping disabled");
      return;
    }
  }
  char prefix[32];
  std::snprintf(prefix, sizeof prefix, "frame%04u_", frame_);
  for (uint32_t v = 0; v < in.viewCount; ++v) {
    const std::string base = dir_ + "/" + prefix + tag_ + (v == 0 ? "_left" : "_right");
    writeImage(vk, in.views[v].color, base + "_in.png", log);
    writeImage(vk, out.views[v], base + "_out.png", log);
  }
  ++frame_;
}

bool ImageDumper::writeImage(core::VulkanContext& vk, const core::ImageRef& ref, const std::string& path,
                             Logger& log) {
  const bool bgra = ref.format == VK_FORMAT_B8G8R8A8_UNORM || ref.format == VK_FORMAT_B8G8R8A8_SRGB;
  const bool rgba = ref.format == VK_FORMAT_R8G8B8A8_UNORM || ref.format == VK_FORMAT_R8G8B8A8_SRGB;
  if (!bgra && !rgba) {
    log.once(LogLevel::Warn, "dump-format", "dump: only 8-bit RGBA/BGRA images are dumped; skipping");
    return false;
  }
  if (ref.usage != 0 && !(ref.usage & VK_IMAGE_USAGE_TRANSFER_SRC_BIT)) {  // a copy from it is invalid
    log.once(LogLevel::Warn, "dump-usage", "dump: an image without TRANSFER_SRC usage is not dumped");
    return false;
  }
  const VkDevice dev = vk.device();
  const uint32_t w = ref.rect.extent.width;
  const uint32_t h = ref.rect.extent.height;
  const VkDeviceSize size = VkDeviceSize{w} * h * 4;

  auto bci = makeVk<VkBufferCreateInfo>(VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO);
  bci.size = size;
  bci.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  VkBuffer rawBuffer = VK_NULL_HANDLE;
  if (vkCreateBuffer(dev, &bci, nullptr, &rawBuffer) != VK_SUCCESS) return false;
  const core::Unique<VkBuffer> buffer(dev, rawBuffer);
  VkMemoryRequirements req{};
  vkGetBufferMemoryRequirements(dev, buffer.get(), &req);
  // Read back by the CPU: cached host memory where offered (uncached reads crawl).
  const uint32_t type = vk.findMemoryType(
      req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT,
      VK_MEMORY_PROPERTY_HOST_CACHED_BIT);
  if (type == UINT32_MAX) return false;
  auto mai = makeVk<VkMemoryAllocateInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO);
  mai.allocationSize = req.size;
  mai.memoryTypeIndex = type;
  VkDeviceMemory rawMemory = VK_NULL_HANDLE;
  if (vkAllocateMemory(dev, &mai, nullptr, &rawMemory) != VK_SUCCESS) return false;
  const core::Unique<VkDeviceMemory> memory(dev, rawMemory);
  if (vkBindBufferMemory(dev, buffer.get(), memory.get(), 0) != VK_SUCCESS) return false;

  auto pci = makeVk<VkCommandPoolCreateInfo>(VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO);
  pci.queueFamilyIndex = vk.queueFamilyIndex();
  pci.flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT;
  VkCommandPool rawPool = VK_NULL_HANDLE;
  if (vkCreateCommandPool(dev, &pci, nullptr, &rawPool) != VK_SUCCESS) return false;
  const core::Unique<VkCommandPool> pool(dev, rawPool);
  auto cai = makeVk<VkCommandBufferAllocateInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO);
  cai.commandPool = pool.get();
  cai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  cai.commandBufferCount = 1;
  VkCommandBuffer cmd = VK_NULL_HANDLE;  // freed with the pool
  if (vkAllocateCommandBuffers(dev, &cai, &cmd) != VK_SUCCESS) return false;
  auto fci = makeVk<VkFenceCreateInfo>(VK_STRUCTURE_TYPE_FENCE_CREATE_INFO);
  VkFence rawFence = VK_NULL_HANDLE;
  if (vkCreateFence(dev, &fci, nullptr, &rawFence) != VK_SUCCESS) return false;
  const core::Unique<VkFence> fence(dev, rawFence);

  const VkImageLayout layout = ref.finalLayout.value_or(ref.layout);
  const VkImageSubresourceRange range{colorAspect(), 0, 1, ref.arrayLayer, 1};
  auto begin = makeVk<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  vkBeginCommandBuffer(cmd, &begin);
  auto toSrc = makeVk<VkImageMemoryBarrier>(VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER);
  toSrc.srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT;
  toSrc.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
  toSrc.oldLayout = layout;
  toSrc.newLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
  toSrc.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  toSrc.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  toSrc.image = ref.image;
  toSrc.subresourceRange = range;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr,
                       0, nullptr, 1, &toSrc);
  VkBufferImageCopy region{};
  region.imageSubresource = {colorAspect(), 0, ref.arrayLayer, 1};
  region.imageOffset = {ref.rect.offset.x, ref.rect.offset.y, 0};
  region.imageExtent = {w, h, 1};
  vkCmdCopyImageToBuffer(cmd, ref.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, buffer.get(), 1, &region);
  VkImageMemoryBarrier back = toSrc;
  back.srcAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
  back.dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
  back.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
  back.newLayout = layout == VK_IMAGE_LAYOUT_UNDEFINED ? VK_IMAGE_LAYOUT_GENERAL : layout;
  auto hostRead = makeVk<VkBufferMemoryBarrier>(VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER);
  hostRead.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  hostRead.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  hostRead.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  hostRead.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  hostRead.buffer = buffer.get();
  hostRead.size = VK_WHOLE_SIZE;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT,
                       VK_PIPELINE_STAGE_ALL_COMMANDS_BIT | VK_PIPELINE_STAGE_HOST_BIT, 0, 0, nullptr, 1,
                       &hostRead, 1, &back);
  vkEndCommandBuffer(cmd);
  auto si = makeVk<VkSubmitInfo>(VK_STRUCTURE_TYPE_SUBMIT_INFO);
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cmd;
  if (vkQueueSubmit(vk.queue(), 1, &si, fence.get()) != VK_SUCCESS) return false;
  if (vkWaitForFences(dev, 1, &rawFence, VK_TRUE, kFenceTimeoutNs) != VK_SUCCESS) {
    // The pool and fence must outlive the work: wait for it without a bound before freeing.
    log.once(LogLevel::Warn, "dump-timeout", "dump: readback took over 2 s");
    vkWaitForFences(dev, 1, &rawFence, VK_TRUE, UINT64_MAX);
  }
  void* mapped = nullptr;
  if (vkMapMemory(dev, memory.get(), 0, size, 0, &mapped) != VK_SUCCESS) return false;
  std::vector<uint8_t> pixels(size);
  std::memcpy(pixels.data(), mapped, size);
  vkUnmapMemory(dev, memory.get());
  if (bgra) {
    for (size_t i = 0; i + 3 < pixels.size(); i += 4) std::swap(pixels[i], pixels[i + 2]);
  }
  if (stbi_write_png(path.c_str(), static_cast<int>(w), static_cast<int>(h), 4, pixels.data(),
                     static_cast<int>(w * 4)) == 0) {
    log.once(LogLevel::Warn, "dump-write", "dump: cannot write " + path);
    return false;
  }
  return true;
}

}  // namespace steadyxr::layer
