// SceneRenderer::Impl's set-up: the command buffer, timestamp queries, the readback buffer, and
// the render targets (per-eye 1-sample and MSAA images, the ground truth's float target, outputs).
#include "renderer_impl.h"

#include <vector>

namespace steadyxr::eval {

bool SceneRenderer::Impl::init(const std::vector<Rgba8>& texData, std::string* error) {
  // Float accumulation target for the ground truth: the first blendable float format.
  for (VkFormat f : {VK_FORMAT_R32G32B32A32_SFLOAT, VK_FORMAT_R16G16B16A16_SFLOAT}) {
    VkFormatProperties fp;
    vkGetPhysicalDeviceFormatProperties(ctx.physicalDevice(), f, &fp);
    if (fp.optimalTilingFeatures & VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BLEND_BIT) {
      accumFormat = f;
      break;
    }
  }
  VkCommandPoolCreateInfo pci{};
  pci.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
  pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pci.queueFamilyIndex = ctx.queueFamilyIndex();
  VkCommandPool cp = VK_NULL_HANDLE;
  if (VkResult r = vkCreateCommandPool(dev, &pci, nullptr, &cp); r != VK_SUCCESS) {
    *error = vkError("vkCreateCommandPool", r);
    return false;
  }
  pool = UniqueCommandPool(dev, cp);
  VkCommandBufferAllocateInfo cai{};
  cai.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
  cai.commandPool = cp;
  cai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  cai.commandBufferCount = 1;
  if (VkResult r = vkAllocateCommandBuffers(dev, &cai, &cmd); r != VK_SUCCESS) {
    *error = vkError("vkAllocateCommandBuffers", r);
    return false;
  }
  VkFenceCreateInfo fci{};
  fci.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
  VkFence f = VK_NULL_HANDLE;
  vkCreateFence(dev, &fci, nullptr, &f);
  fence = UniqueFence(dev, f);

  uint32_t familyCount = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(ctx.physicalDevice(), &familyCount, nullptr);
  std::vector<VkQueueFamilyProperties> families(familyCount);
  vkGetPhysicalDeviceQueueFamilyProperties(ctx.physicalDevice(), &familyCount, families.data());
  if (ctx.queueFamilyIndex() < familyCount && families[ctx.queueFamilyIndex()].timestampValidBits > 0) {
    VkQueryPoolCreateInfo qci{};
    qci.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO;
    qci.queryType = VK_QUERY_TYPE_TIMESTAMP;
    qci.queryCount = 2;
    VkQueryPool qp = VK_NULL_HANDLE;
    if (vkCreateQueryPool(dev, &qci, nullptr, &qp) == VK_SUCCESS) {
      queries = UniqueQueryPool(dev, qp);
      timestamps = true;
      timestampPeriodNs = ctx.properties().limits.timestampPeriod;
    }
  }

  VkBufferCreateInfo bci{};
  bci.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
  bci.size = VkDeviceSize(width) * height * 16;
  bci.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  VkBuffer buf = VK_NULL_HANDLE;
  if (VkResult r = vkCreateBuffer(dev, &bci, nullptr, &buf); r != VK_SUCCESS) {
    *error = vkError("vkCreateBuffer", r);
    return false;
  }
  staging = UniqueBuffer(dev, buf);
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(dev, buf, &req);
  // Read by the CPU every frame: cached host memory where offered (uncached reads crawl).
  if (!allocate(req, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT,
                &stagingMemory, error, VK_MEMORY_PROPERTY_HOST_CACHED_BIT)) {
    return false;
  }
  vkBindBufferMemory(dev, buf, stagingMemory.get(), 0);
  vkMapMemory(dev, stagingMemory.get(), 0, VK_WHOLE_SIZE, 0, &stagingPtr);
  return initTextures(texData, error) && initTargets(error);
}

bool SceneRenderer::Impl::initTargets(std::string* error) {
  const VkPhysicalDeviceLimits& limits = ctx.properties().limits;
  const VkSampleCountFlags counts = limits.framebufferColorSampleCounts & limits.framebufferDepthSampleCounts;
  msaaSupported = {(counts & VK_SAMPLE_COUNT_2_BIT) != 0, (counts & VK_SAMPLE_COUNT_4_BIT) != 0};
  const uint32_t w = uint32_t(width), h = uint32_t(height);
  if (!makeRenderPass(eyeFormat, VK_SAMPLE_COUNT_1_BIT, true, &basePass, error) ||
      !makePipeline(basePass.get(), VK_SAMPLE_COUNT_1_BIT, false, &basePipeline, error)) {
    return false;
  }
  for (int eye = 0; eye < 2; ++eye) {
    if (!makeImage(eyeFormat,
                   VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
                       VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                   VK_SAMPLE_COUNT_1_BIT, w, h, &baseColor[eye], error) ||
        !makeImage(kDepthFormat,
                   VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
                       VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                   VK_SAMPLE_COUNT_1_BIT, w, h, &baseDepth[eye], error) ||
        !makeFramebuffer(basePass.get(), {baseColor[eye].view.get(), baseDepth[eye].view.get()}, &baseFb[eye],
                         error)) {
      return false;
    }
    // sRGB outputs are written through a UNORM storage view, as the layer writes sRGB swapchains.
    if (!makeImage(eyeFormat,
                   VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT |
                       VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_SAMPLED_BIT,
                   VK_SAMPLE_COUNT_1_BIT, w, h, &outputs[eye], error, 1,
                   options.srgb ? VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT : 0)) {
      return false;
    }
  }
  for (int i = 0; i < 2; ++i) {
    if (!msaaSupported[i]) continue;
    const VkSampleCountFlagBits sc = i == 0 ? VK_SAMPLE_COUNT_2_BIT : VK_SAMPLE_COUNT_4_BIT;
    if (!makeRenderPass(eyeFormat, sc, false, &msaaPass[i], error) ||
        !makePipeline(msaaPass[i].get(), sc, false, &msaaPipeline[i], error) ||
        !makeImage(eyeFormat, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSIENT_ATTACHMENT_BIT,
                   sc, w, h, &msaaColor[i], error) ||
        !makeImage(kDepthFormat,
                   VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSIENT_ATTACHMENT_BIT, sc,
                   w, h, &msaaDepth[i], error)) {
      return false;
    }
    for (int eye = 0; eye < 2; ++eye) {
      if (!makeImage(eyeFormat,
                     VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
                         VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                     VK_SAMPLE_COUNT_1_BIT, w, h, &msaaResolve[i][eye], error) ||
          !makeFramebuffer(msaaPass[i].get(),
                           {msaaColor[i].view.get(), msaaDepth[i].view.get(), msaaResolve[i][eye].view.get()},
                           &msaaFb[i][eye], error)) {
        return false;
      }
    }
  }
  if (!makeRenderPass(accumFormat, VK_SAMPLE_COUNT_1_BIT, false, &gtPass, error) ||
      !makePipeline(gtPass.get(), VK_SAMPLE_COUNT_1_BIT, true, &gtPipeline, error) ||
      !makeImage(accumFormat, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                 VK_SAMPLE_COUNT_1_BIT, w, h, &gtColor, error) ||
      !makeImage(kDepthFormat, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT, VK_SAMPLE_COUNT_1_BIT, w, h,
                 &gtDepth, error) ||
      !makeFramebuffer(gtPass.get(), {gtColor.view.get(), gtDepth.view.get()}, &gtFb, error)) {
    return false;
  }
  // Every image the filter reads or writes lives in GENERAL from here on.
  if (!beginImpl(error)) return false;
  for (int eye = 0; eye < 2; ++eye) {
    toGeneral(baseColor[eye].image.get(), VK_IMAGE_ASPECT_COLOR_BIT);
    toGeneral(baseDepth[eye].image.get(), VK_IMAGE_ASPECT_DEPTH_BIT);
    toGeneral(outputs[eye].image.get(), VK_IMAGE_ASPECT_COLOR_BIT);
    for (int i = 0; i < 2; ++i) {
      if (msaaSupported[i]) toGeneral(msaaResolve[i][eye].image.get(), VK_IMAGE_ASPECT_COLOR_BIT);
    }
  }
  return submitAndWait(error);
}

}  // namespace steadyxr::eval
