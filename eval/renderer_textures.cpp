// SceneRenderer::Impl's textures: mip chains uploaded (sRGB or UNORM), the trilinear sampler,
// the descriptor sets and the pipeline layout the scene shaders bind them with.
#include "renderer_impl.h"

#include <algorithm>
#include <cstring>

namespace steadyxr::eval {

bool SceneRenderer::Impl::uploadTexture(const Rgba8& src, std::string* error) {
  // Trilinear sampling needs the whole chain, built on the CPU (box filter in the texture's own
  // colour space: linear light for sRGB textures).
  const std::vector<Rgba8> levels = options.mipmaps ? mipChain(src, options.srgb) : std::vector<Rgba8>{src};
  size_t bytes = 0;
  for (const Rgba8& l : levels) bytes += l.pixels.size();
  GpuImage tex;
  if (!makeImage(eyeFormat, VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT,
                 VK_SAMPLE_COUNT_1_BIT, uint32_t(src.width), uint32_t(src.height), &tex, error,
                 uint32_t(levels.size()))) {
    return false;
  }
  // A staging buffer of its own: textures may be larger than the readback buffer.
  VkBufferCreateInfo bci{};
  bci.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
  bci.size = bytes;
  bci.usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
  VkBuffer buf = VK_NULL_HANDLE;
  if (VkResult r = vkCreateBuffer(dev, &bci, nullptr, &buf); r != VK_SUCCESS) {
    *error = vkError("vkCreateBuffer", r);
    return false;
  }
  UniqueBuffer buffer(dev, buf);
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(dev, buf, &req);
  UniqueMemory mem;
  if (!allocate(req, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT, &mem,
                error)) {
    return false;
  }
  vkBindBufferMemory(dev, buf, mem.get(), 0);
  void* ptr = nullptr;
  vkMapMemory(dev, mem.get(), 0, VK_WHOLE_SIZE, 0, &ptr);
  std::vector<VkBufferImageCopy> regions;
  size_t offset = 0;
  for (size_t i = 0; i < levels.size(); ++i) {
    std::memcpy(static_cast<uint8_t*>(ptr) + offset, levels[i].pixels.data(), levels[i].pixels.size());
    VkBufferImageCopy region{};
    region.bufferOffset = offset;
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, uint32_t(i), 0, 1};
    region.imageExtent = {uint32_t(levels[i].width), uint32_t(levels[i].height), 1};
    regions.push_back(region);
    offset += levels[i].pixels.size();
  }
  vkUnmapMemory(dev, mem.get());
  if (!beginImpl(error)) return false;
  VkImageMemoryBarrier b{};
  b.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
  b.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  b.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  b.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
  b.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.image = tex.image.get();
  b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, uint32_t(levels.size()), 0, 1};
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr,
                       0, nullptr, 1, &b);
  vkCmdCopyBufferToImage(cmd, buf, tex.image.get(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                         uint32_t(regions.size()), regions.data());
  b.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  b.dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
  b.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
  b.newLayout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT, 0, 0,
                       nullptr, 0, nullptr, 1, &b);
  if (!submitAndWait(error)) return false;
  textures.push_back(std::move(tex));
  return true;
}

bool SceneRenderer::Impl::initTextures(const std::vector<Rgba8>& texData, std::string* error) {
  VkSamplerCreateInfo sci{};
  sci.sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO;
  sci.magFilter = VK_FILTER_LINEAR;
  sci.minFilter = VK_FILTER_LINEAR;
  // Trilinear, as real apps sample; without mipmaps minified textures alias (seed 003's viewer,
  // the worst case).
  sci.mipmapMode = options.mipmaps ? VK_SAMPLER_MIPMAP_MODE_LINEAR : VK_SAMPLER_MIPMAP_MODE_NEAREST;
  sci.addressModeU = sci.addressModeV = sci.addressModeW = VK_SAMPLER_ADDRESS_MODE_REPEAT;
  sci.maxLod = options.mipmaps ? VK_LOD_CLAMP_NONE : 0.0f;
  VkSampler s = VK_NULL_HANDLE;
  vkCreateSampler(dev, &sci, nullptr, &s);
  sampler = UniqueSampler(dev, s);

  VkDescriptorSetLayoutBinding binding{0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1,
                                       VK_SHADER_STAGE_FRAGMENT_BIT, nullptr};
  VkDescriptorSetLayoutCreateInfo lci{};
  lci.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
  lci.bindingCount = 1;
  lci.pBindings = &binding;
  VkDescriptorSetLayout sl = VK_NULL_HANDLE;
  vkCreateDescriptorSetLayout(dev, &lci, nullptr, &sl);
  setLayout = UniqueSetLayout(dev, sl);
  VkPushConstantRange range{VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
                            sizeof(PushConstants)};
  VkPipelineLayoutCreateInfo plci{};
  plci.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
  plci.setLayoutCount = 1;
  plci.pSetLayouts = &sl;
  plci.pushConstantRangeCount = 1;
  plci.pPushConstantRanges = &range;
  VkPipelineLayout pl = VK_NULL_HANDLE;
  vkCreatePipelineLayout(dev, &plci, nullptr, &pl);
  pipelineLayout = UniquePipelineLayout(dev, pl);

  for (const Rgba8& t : texData) {
    if (!uploadTexture(t, error)) return false;
  }
  const uint32_t n = static_cast<uint32_t>(std::max<size_t>(1, textures.size()));
  VkDescriptorPoolSize ps{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, n};
  VkDescriptorPoolCreateInfo dpci{};
  dpci.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
  dpci.maxSets = n;
  dpci.poolSizeCount = 1;
  dpci.pPoolSizes = &ps;
  VkDescriptorPool dp = VK_NULL_HANDLE;
  vkCreateDescriptorPool(dev, &dpci, nullptr, &dp);
  descriptorPool = UniqueDescriptorPool(dev, dp);
  for (const GpuImage& t : textures) {
    VkDescriptorSetAllocateInfo dai{};
    dai.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
    dai.descriptorPool = dp;
    dai.descriptorSetCount = 1;
    dai.pSetLayouts = &sl;
    VkDescriptorSet set = VK_NULL_HANDLE;
    if (VkResult r = vkAllocateDescriptorSets(dev, &dai, &set); r != VK_SUCCESS) {
      *error = vkError("vkAllocateDescriptorSets", r);
      return false;
    }
    VkDescriptorImageInfo ii{sampler.get(), t.view.get(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
    VkWriteDescriptorSet w{};
    w.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    w.dstSet = set;
    w.descriptorCount = 1;
    w.descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    w.pImageInfo = &ii;
    vkUpdateDescriptorSets(dev, 1, &w, 0, nullptr);
    textureSets.push_back(set);
  }
  return true;
}

}  // namespace steadyxr::eval
