// The probe's per-frame work: rendering a pattern into a swapchain image, and the invalid
// xrEndFrame calls.
#include "probe_util.h"

#include <array>
#include <cmath>

namespace probe {

// Acquire, wait, fill every layer with a moving pattern (colour with edges; alpha varied per
// pixel when translucent, premultiplied into the colour), release.
bool Xr::render(Swapchain& sc, uint32_t w, uint32_t h, uint32_t layers, int frame, bool translucent) {
  uint32_t index = 0;
  if (XR_FAILED(xrAcquireSwapchainImage(sc.handle, nullptr, &index))) return false;
  auto wi = xrStruct<XrSwapchainImageWaitInfo>(XR_TYPE_SWAPCHAIN_IMAGE_WAIT_INFO);
  wi.timeout = XR_INFINITE_DURATION;
  if (XR_FAILED(xrWaitSwapchainImage(sc.handle, &wi))) return false;
  const bool half = sc.format == VK_FORMAT_R16G16B16A16_SFLOAT;
  const VkDeviceSize px = half ? 8 : 4, size = VkDeviceSize{w} * h * layers * px;
  VkBuffer buf = VK_NULL_HANDLE;
  VkDeviceMemory mem = VK_NULL_HANDLE;
  auto bci = vkStruct<VkBufferCreateInfo>(VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO);
  bci.size = size;
  bci.usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
  vkCreateBuffer(device_, &bci, nullptr, &buf);
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(device_, buf, &req);
  VkPhysicalDeviceMemoryProperties mp;
  vkGetPhysicalDeviceMemoryProperties(physical_, &mp);
  auto mai = vkStruct<VkMemoryAllocateInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO);
  mai.allocationSize = req.size;
  for (uint32_t i = 0; i < mp.memoryTypeCount; ++i)
    if ((req.memoryTypeBits & (1u << i)) &&
        (mp.memoryTypes[i].propertyFlags &
         (VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT)) ==
            (VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT)) {
      mai.memoryTypeIndex = i;
      break;
    }
  vkAllocateMemory(device_, &mai, nullptr, &mem);
  vkBindBufferMemory(device_, buf, mem, 0);
  if (!sc.depth) {
    void* mapped = nullptr;
    vkMapMemory(device_, mem, 0, size, 0, &mapped);
    auto* b8 = static_cast<uint8_t*>(mapped);
    auto* b16 = static_cast<uint16_t*>(mapped);
    for (uint32_t l = 0; l < layers; ++l)
      for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
          const size_t i = (size_t{l} * h + y) * w + x;
          const bool edge = ((x + uint32_t(frame)) / 6 + y / 6 + l) % 2 != 0;
          const float a = translucent ? float((x * 7 + y * 3 + uint32_t(frame)) % 256) / 255.0f : 1.0f;
          const float c[4] = {(edge ? 0.9f : 0.1f) * a, 0.5f * a, (edge ? 0.2f : 0.8f) * a, a};
          for (int k = 0; k < 4; ++k) {
            if (half)
              b16[i * 4 + k] = toHalf(c[k]);
            else
              b8[i * 4 + k] = static_cast<uint8_t>(std::lround(c[k] * 255.0f));
          }
        }
    vkUnmapMemory(device_, mem);
  }
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  auto cai = vkStruct<VkCommandBufferAllocateInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO);
  cai.commandPool = pool_;
  cai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  cai.commandBufferCount = 1;
  vkAllocateCommandBuffers(device_, &cai, &cmd);
  auto begin = vkStruct<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  vkBeginCommandBuffer(cmd, &begin);
  const VkImageAspectFlags aspect = sc.depth ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT;
  const VkImageLayout attach =
      sc.depth ? VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL : VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
  auto b = vkStruct<VkImageMemoryBarrier>(VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER);
  b.srcAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
  b.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  b.oldLayout = attach;
  b.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
  b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.image = sc.images[index];
  b.subresourceRange = {aspect, 0, 1, 0, layers};
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr,
                       0, nullptr, 1, &b);
  if (sc.depth) {
    const VkClearDepthStencilValue v{0.5f, 0};
    vkCmdClearDepthStencilImage(cmd, sc.images[index], VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &v, 1,
                                &b.subresourceRange);
  } else {
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, layers};
    region.imageExtent = {w, h, 1};
    vkCmdCopyBufferToImage(cmd, buf, sc.images[index], VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
  }
  b.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  b.dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
  b.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
  b.newLayout = attach;  // what the Vulkan binding requires at release
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 0, nullptr,
                       0, nullptr, 1, &b);
  vkEndCommandBuffer(cmd);
  auto si = vkStruct<VkSubmitInfo>(VK_STRUCTURE_TYPE_SUBMIT_INFO);
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cmd;
  vkQueueSubmit(queue_, 1, &si, VK_NULL_HANDLE);
  vkQueueWaitIdle(queue_);
  vkFreeCommandBuffers(device_, pool_, 1, &cmd);
  vkDestroyBuffer(device_, buf, nullptr);
  vkFreeMemory(device_, mem, nullptr);
  return XR_SUCCEEDED(xrReleaseSwapchainImage(sc.handle, nullptr));
}

// The invalid xrEndFrame calls of issue 15; each result is printed so that a run without the
// layer can be compared (tests/layer/probe/run_probe.sh). A frame the call did not end is
// ended with no layers.
std::string Xr::invalidCalls(XrSession session, XrSpace space, Swapchain& sc) {
  std::string out;
  auto views = std::array<XrCompositionLayerProjectionView, 3>{};
  for (uint32_t v = 0; v < 3; ++v) {
    views[v] = xrStruct<XrCompositionLayerProjectionView>(XR_TYPE_COMPOSITION_LAYER_PROJECTION_VIEW);
    views[v].pose.orientation.w = 1.0f;
    views[v].fov = {-0.7f, 0.7f, 0.7f, -0.7f};
    views[v].subImage.swapchain = sc.handle;
    views[v].subImage.imageRect = {{int32_t(v % 2 * (sc.width / 2)), 0},
                                   {int32_t(sc.width / 2), int32_t(sc.height)}};
  }
  auto proj = xrStruct<XrCompositionLayerProjection>(XR_TYPE_COMPOSITION_LAYER_PROJECTION);
  proj.space = space;
  proj.viewCount = 2;
  proj.views = views.data();
  auto nullViews = proj;
  nullViews.views = nullptr;
  auto threeViews = proj;
  threeViews.viewCount = 3;
  const auto* good = reinterpret_cast<const XrCompositionLayerBaseHeader*>(&proj);
  std::vector<const XrCompositionLayerBaseHeader*> tooMany(maxLayers_ + 1, good);
  const XrCompositionLayerBaseHeader* nullEntry[] = {nullptr};
  const XrCompositionLayerBaseHeader* nullViewsLayer[] = {
      reinterpret_cast<const XrCompositionLayerBaseHeader*>(&nullViews)};
  const XrCompositionLayerBaseHeader* threeViewsLayer[] = {
      reinterpret_cast<const XrCompositionLayerBaseHeader*>(&threeViews)};
  struct Call {
    const char* name;
    uint32_t count;
    const XrCompositionLayerBaseHeader* const* layers;
  };
  const Call calls[] = {{"layers_null", 1, nullptr},
                        {"layer_entry_null", 1, nullEntry},
                        {"layer_count_over_max", maxLayers_ + 1, tooMany.data()},
                        {"views_null", 1, nullViewsLayer},
                        {"view_count_3", 1, threeViewsLayer}};
  for (const Call& c : calls) {
    auto fs = xrStruct<XrFrameState>(XR_TYPE_FRAME_STATE);
    xrWaitFrame(session, nullptr, &fs);
    xrBeginFrame(session, nullptr);
    if (!render(sc, sc.width, sc.height, 1, 0, false)) return "render failed";
    auto ei = xrStruct<XrFrameEndInfo>(XR_TYPE_FRAME_END_INFO);
    ei.displayTime = fs.predictedDisplayTime;
    ei.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
    ei.layerCount = c.count;
    ei.layers = c.layers;
    const XrResult r = xrEndFrame(session, &ei);
    out += std::string(" ") + c.name + "=" + resultName(instance_, r);
    if (XR_FAILED(r)) {
      ei.layerCount = 0;
      ei.layers = nullptr;
      xrEndFrame(session, &ei);
    }
  }
  if (api_ == Api::V2) {  // xrCreateVulkanInstanceKHR without a VkInstanceCreateInfo
    auto xci = xrStruct<XrVulkanInstanceCreateInfoKHR>(XR_TYPE_VULKAN_INSTANCE_CREATE_INFO_KHR);
    xci.systemId = system_;
    xci.pfnGetInstanceProcAddr = vkGetInstanceProcAddr;
    VkInstance vi = VK_NULL_HANDLE;
    VkResult vr = VK_SUCCESS;
    const XrResult r = xrFn<PFN_xrCreateVulkanInstanceKHR>(instance_, "xrCreateVulkanInstanceKHR")(
        instance_, &xci, &vi, &vr);
    out += " vulkan_create_info_null=" + resultName(instance_, r);
    if (XR_SUCCEEDED(r) && vi) vkDestroyInstance(vi, nullptr);
  }
  return out;
}

}  // namespace probe
