// SceneRenderer::Impl's Vulkan plumbing: memory, images with views, the one-shot command buffer,
// barriers, timestamps and copies into the readback buffer.
#include "renderer_impl.h"

namespace steadyxr::eval {

bool SceneRenderer::Impl::allocate(VkMemoryRequirements req, VkMemoryPropertyFlags flags, UniqueMemory* out,
                                   std::string* error, VkMemoryPropertyFlags preferred) {
  const uint32_t type = ctx.findMemoryType(req.memoryTypeBits, flags, preferred);
  if (type == UINT32_MAX) {
    *error = "no suitable memory type";
    return false;
  }
  VkMemoryAllocateInfo ai{};
  ai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
  ai.allocationSize = req.size;
  ai.memoryTypeIndex = type;
  VkDeviceMemory mem = VK_NULL_HANDLE;
  if (VkResult r = vkAllocateMemory(dev, &ai, nullptr, &mem); r != VK_SUCCESS) {
    *error = vkError("vkAllocateMemory", r);
    return false;
  }
  *out = UniqueMemory(dev, mem);
  return true;
}

bool SceneRenderer::Impl::makeImage(VkFormat format, VkImageUsageFlags usage, VkSampleCountFlagBits samples,
                                    uint32_t w, uint32_t h, GpuImage* out, std::string* error,
                                    uint32_t mipLevels, VkImageCreateFlags flags) {
  VkImageCreateInfo ci{};
  ci.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
  ci.flags = flags;
  ci.imageType = VK_IMAGE_TYPE_2D;
  ci.format = format;
  ci.extent = {w, h, 1};
  ci.mipLevels = mipLevels;
  ci.arrayLayers = 1;
  ci.samples = samples;
  ci.tiling = VK_IMAGE_TILING_OPTIMAL;
  ci.usage = usage;
  ci.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  VkImage img = VK_NULL_HANDLE;
  if (VkResult r = vkCreateImage(dev, &ci, nullptr, &img); r != VK_SUCCESS) {
    *error = vkError("vkCreateImage", r);
    return false;
  }
  out->image = UniqueImage(dev, img);
  out->format = format;
  out->usage = usage;
  out->mutableFormat = (flags & VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT) != 0;
  VkMemoryRequirements req;
  vkGetImageMemoryRequirements(dev, img, &req);
  if (!allocate(req, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, &out->memory, error)) return false;
  vkBindImageMemory(dev, img, out->memory.get(), 0);
  const bool depth = format == kDepthFormat;
  VkImageViewCreateInfo vi{};
  vi.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
  vi.image = img;
  vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
  vi.format = format;
  vi.subresourceRange = {
      depth ? VkImageAspectFlags(VK_IMAGE_ASPECT_DEPTH_BIT) : VkImageAspectFlags(VK_IMAGE_ASPECT_COLOR_BIT),
      0, mipLevels, 0, 1};
  VkImageView view = VK_NULL_HANDLE;
  if (VkResult r = vkCreateImageView(dev, &vi, nullptr, &view); r != VK_SUCCESS) {
    *error = vkError("vkCreateImageView", r);
    return false;
  }
  out->view = UniqueImageView(dev, view);
  return true;
}

bool SceneRenderer::Impl::beginImpl(std::string* error) {
  VkFence f = fence.get();
  vkResetFences(dev, 1, &f);
  vkResetCommandBuffer(cmd, 0);
  VkCommandBufferBeginInfo bi{};
  bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  if (VkResult r = vkBeginCommandBuffer(cmd, &bi); r != VK_SUCCESS) {
    *error = vkError("vkBeginCommandBuffer", r);
    return false;
  }
  return true;
}

bool SceneRenderer::Impl::submitAndWait(std::string* error) {
  vkEndCommandBuffer(cmd);
  VkSubmitInfo si{};
  si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cmd;
  if (VkResult r = vkQueueSubmit(ctx.queue(), 1, &si, fence.get()); r != VK_SUCCESS) {
    *error = vkError("vkQueueSubmit", r);
    return false;
  }
  VkFence f = fence.get();
  if (VkResult r = vkWaitForFences(dev, 1, &f, VK_TRUE, UINT64_MAX); r != VK_SUCCESS) {
    *error = vkError("vkWaitForFences", r);
    return false;
  }
  return true;
}

void SceneRenderer::Impl::globalBarrier(VkAccessFlags src, VkAccessFlags dst) {
  VkMemoryBarrier mb{};
  mb.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
  mb.srcAccessMask = src;
  mb.dstAccessMask = dst;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 1, &mb,
                       0, nullptr, 0, nullptr);
}

void SceneRenderer::Impl::toGeneral(VkImage image, VkImageAspectFlags aspect) {
  VkImageMemoryBarrier b{};
  b.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
  b.srcAccessMask = 0;
  b.dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
  b.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  b.newLayout = VK_IMAGE_LAYOUT_GENERAL;
  b.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.image = image;
  b.subresourceRange = {aspect, 0, 1, 0, 1};
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 0,
                       nullptr, 0, nullptr, 1, &b);
}

void SceneRenderer::Impl::readTimestamps(double* gpuMs) {
  if (!timestamps || gpuMs == nullptr) return;
  uint64_t t[2] = {0, 0};
  if (vkGetQueryPoolResults(dev, queries.get(), 0, 2, sizeof(t), t, sizeof(uint64_t),
                            VK_QUERY_RESULT_64_BIT) == VK_SUCCESS) {
    *gpuMs = double(t[1] - t[0]) * timestampPeriodNs * 1e-6;
  }
}

void SceneRenderer::Impl::copyToStaging(VkImage image, VkImageAspectFlags aspect, VkDeviceSize offset) {
  VkBufferImageCopy region{};
  region.bufferOffset = offset;
  region.imageSubresource = {aspect, 0, 0, 1};
  region.imageExtent = {uint32_t(width), uint32_t(height), 1};
  vkCmdCopyImageToBuffer(cmd, image, VK_IMAGE_LAYOUT_GENERAL, staging.get(), 1, &region);
}

void SceneRenderer::Impl::hostBarrier() {
  VkMemoryBarrier mb{};
  mb.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
  mb.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  mb.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &mb, 0, nullptr,
                       0, nullptr);
}

}  // namespace steadyxr::eval
