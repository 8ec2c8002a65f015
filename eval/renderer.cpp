#include "renderer.h"

#include "vk_handles.h"

#include "eval_scene_frag.h"
#include "eval_scene_vert.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

#include <glm/gtc/matrix_transform.hpp>

namespace steadyxr::eval {

namespace {

constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;

struct PushConstants {
  glm::mat4 mvp;
  glm::vec4 tint;
  glm::vec4 uvST;
  glm::vec4 noise;
};
static_assert(sizeof(PushConstants) == 112);

std::string vkError(const char* what, VkResult r) {
  return std::string(what) + " failed (VkResult " + std::to_string(r) + ")";
}

}  // namespace

struct GpuImage {
  UniqueImage image;
  UniqueMemory memory;
  UniqueImageView view;
  VkFormat format = VK_FORMAT_UNDEFINED;
  VkImageUsageFlags usage = 0;
  bool mutableFormat = false;
};

struct SceneRenderer::Impl {
  core::VulkanContext& ctx;
  VkDevice dev;
  int width;
  int height;
  RenderOptions options;
  // sRGB: the eye images, MSAA targets, outputs and textures are sRGB (shading and blending in
  // linear light, as the layer's filter reads them); UNORM: everything in encoded values.
  VkFormat eyeFormat = VK_FORMAT_R8G8B8A8_SRGB;
  VkFormat accumFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
  bool timestamps = false;
  double timestampPeriodNs = 1.0;

  UniqueCommandPool pool;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  UniqueFence fence;
  UniqueQueryPool queries;
  UniqueBuffer staging;
  UniqueMemory stagingMemory;
  void* stagingPtr = nullptr;

  UniqueSampler sampler;
  UniqueSetLayout setLayout;
  UniqueDescriptorPool descriptorPool;
  std::vector<GpuImage> textures;
  std::vector<VkDescriptorSet> textureSets;
  UniquePipelineLayout pipelineLayout;

  // Base (1 sample): per eye colour + depth.
  UniqueRenderPass basePass;
  UniquePipeline basePipeline;
  std::array<GpuImage, 2> baseColor, baseDepth;
  std::array<UniqueFramebuffer, 2> baseFb;
  // MSAA, index 0 = 2x, 1 = 4x (lavapipe offers 4x only).
  std::array<bool, 2> msaaSupported{false, false};
  std::array<UniqueRenderPass, 2> msaaPass;
  std::array<UniquePipeline, 2> msaaPipeline;
  std::array<GpuImage, 2> msaaColor, msaaDepth;
  std::array<std::array<GpuImage, 2>, 2> msaaResolve;
  std::array<std::array<UniqueFramebuffer, 2>, 2> msaaFb;
  // Ground truth accumulation.
  UniqueRenderPass gtPass;
  UniquePipeline gtPipeline;
  GpuImage gtColor, gtDepth;
  UniqueFramebuffer gtFb;
  // Filter outputs.
  std::array<GpuImage, 2> outputs;

  Impl(core::VulkanContext& c, int w, int h, RenderOptions o)
      : ctx(c),
        dev(c.device()),
        width(w),
        height(h),
        options(o),
        eyeFormat(o.srgb ? VK_FORMAT_R8G8B8A8_SRGB : VK_FORMAT_R8G8B8A8_UNORM) {}

  bool allocate(VkMemoryRequirements req, VkMemoryPropertyFlags flags, UniqueMemory* out, std::string* error,
                VkMemoryPropertyFlags preferred = 0) {
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

  bool makeImage(VkFormat format, VkImageUsageFlags usage, VkSampleCountFlagBits samples, uint32_t w,
                 uint32_t h, GpuImage* out, std::string* error, uint32_t mipLevels = 1,
                 VkImageCreateFlags flags = 0) {
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

  bool beginImpl(std::string* error) {
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
  bool submitAndWait(std::string* error) {
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

  void globalBarrier(VkAccessFlags src, VkAccessFlags dst) {
    VkMemoryBarrier mb{};
    mb.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    mb.srcAccessMask = src;
    mb.dstAccessMask = dst;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 1,
                         &mb, 0, nullptr, 0, nullptr);
  }

  void toGeneral(VkImage image, VkImageAspectFlags aspect) {
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

  bool makeRenderPass(VkFormat attachmentFormat, VkSampleCountFlagBits samples, bool storeDepth,
                      UniqueRenderPass* out, std::string* error) {
    const bool msaa = samples != VK_SAMPLE_COUNT_1_BIT;
    std::vector<VkAttachmentDescription> atts;
    VkAttachmentDescription color{};
    color.format = attachmentFormat;
    color.samples = samples;
    color.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
    color.storeOp = msaa ? VK_ATTACHMENT_STORE_OP_DONT_CARE : VK_ATTACHMENT_STORE_OP_STORE;
    color.stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
    color.stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
    color.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    color.finalLayout = msaa ? VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL : VK_IMAGE_LAYOUT_GENERAL;
    atts.push_back(color);
    VkAttachmentDescription depth = color;
    depth.format = kDepthFormat;
    depth.storeOp = storeDepth ? VK_ATTACHMENT_STORE_OP_STORE : VK_ATTACHMENT_STORE_OP_DONT_CARE;
    depth.finalLayout =
        storeDepth ? VK_IMAGE_LAYOUT_GENERAL : VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
    atts.push_back(depth);
    if (msaa) {
      VkAttachmentDescription resolve = color;
      resolve.samples = VK_SAMPLE_COUNT_1_BIT;
      resolve.loadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
      resolve.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
      resolve.finalLayout = VK_IMAGE_LAYOUT_GENERAL;
      atts.push_back(resolve);
    }
    VkAttachmentReference colorRef{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
    VkAttachmentReference depthRef{1, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
    VkAttachmentReference resolveRef{2, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
    VkSubpassDescription sub{};
    sub.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
    sub.colorAttachmentCount = 1;
    sub.pColorAttachments = &colorRef;
    sub.pResolveAttachments = msaa ? &resolveRef : nullptr;
    sub.pDepthStencilAttachment = &depthRef;
    // Earlier readers (the filter's compute passes, copies) finish before we overwrite.
    std::array<VkSubpassDependency, 2> deps{};
    deps[0].srcSubpass = VK_SUBPASS_EXTERNAL;
    deps[0].dstSubpass = 0;
    deps[0].srcStageMask = VK_PIPELINE_STAGE_ALL_COMMANDS_BIT;
    deps[0].dstStageMask = VK_PIPELINE_STAGE_ALL_GRAPHICS_BIT;
    deps[0].srcAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
    deps[0].dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT |
                            VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT |
                            VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_READ_BIT;
    deps[1].srcSubpass = 0;
    deps[1].dstSubpass = VK_SUBPASS_EXTERNAL;
    deps[1].srcStageMask = VK_PIPELINE_STAGE_ALL_GRAPHICS_BIT;
    deps[1].dstStageMask = VK_PIPELINE_STAGE_ALL_COMMANDS_BIT;
    deps[1].srcAccessMask =
        VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
    deps[1].dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
    VkRenderPassCreateInfo ci{};
    ci.sType = VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO;
    ci.attachmentCount = static_cast<uint32_t>(atts.size());
    ci.pAttachments = atts.data();
    ci.subpassCount = 1;
    ci.pSubpasses = &sub;
    ci.dependencyCount = static_cast<uint32_t>(deps.size());
    ci.pDependencies = deps.data();
    VkRenderPass rp = VK_NULL_HANDLE;
    if (VkResult r = vkCreateRenderPass(dev, &ci, nullptr, &rp); r != VK_SUCCESS) {
      *error = vkError("vkCreateRenderPass", r);
      return false;
    }
    *out = UniqueRenderPass(dev, rp);
    return true;
  }

  bool makeFramebuffer(VkRenderPass rp, std::vector<VkImageView> views, UniqueFramebuffer* out,
                       std::string* error) {
    VkFramebufferCreateInfo ci{};
    ci.sType = VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO;
    ci.renderPass = rp;
    ci.attachmentCount = static_cast<uint32_t>(views.size());
    ci.pAttachments = views.data();
    ci.width = static_cast<uint32_t>(width);
    ci.height = static_cast<uint32_t>(height);
    ci.layers = 1;
    VkFramebuffer fb = VK_NULL_HANDLE;
    if (VkResult r = vkCreateFramebuffer(dev, &ci, nullptr, &fb); r != VK_SUCCESS) {
      *error = vkError("vkCreateFramebuffer", r);
      return false;
    }
    *out = UniqueFramebuffer(dev, fb);
    return true;
  }

  bool makePipeline(VkRenderPass rp, VkSampleCountFlagBits samples, bool additive, UniquePipeline* out,
                    std::string* error) {
    auto module = [&](const uint32_t* code, size_t bytes, UniqueShaderModule* m) {
      VkShaderModuleCreateInfo ci{};
      ci.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
      ci.codeSize = bytes;
      ci.pCode = code;
      VkShaderModule sm = VK_NULL_HANDLE;
      if (vkCreateShaderModule(dev, &ci, nullptr, &sm) != VK_SUCCESS) return false;
      *m = UniqueShaderModule(dev, sm);
      return true;
    };
    UniqueShaderModule vs, fs;
    if (!module(kEvalSceneVert, sizeof(kEvalSceneVert), &vs) ||
        !module(kEvalSceneFrag, sizeof(kEvalSceneFrag), &fs)) {
      *error = "vkCreateShaderModule failed";
      return false;
    }
    std::array<VkPipelineShaderStageCreateInfo, 2> stages{};
    stages[0].sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
    stages[0].module = vs.get();
    stages[0].pName = "main";
    stages[1] = stages[0];
    stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
    stages[1].module = fs.get();
    VkPipelineVertexInputStateCreateInfo vi{};
    vi.sType = VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO;
    VkPipelineInputAssemblyStateCreateInfo ia{};
    ia.sType = VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO;
    ia.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
    VkViewport viewport{0.0f, 0.0f, float(width), float(height), 0.0f, 1.0f};
    VkRect2D scissor{{0, 0}, {uint32_t(width), uint32_t(height)}};
    VkPipelineViewportStateCreateInfo vp{};
    vp.sType = VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO;
    vp.viewportCount = 1;
    vp.pViewports = &viewport;
    vp.scissorCount = 1;
    vp.pScissors = &scissor;
    VkPipelineRasterizationStateCreateInfo rs{};
    rs.sType = VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO;
    rs.polygonMode = VK_POLYGON_MODE_FILL;
    rs.cullMode = VK_CULL_MODE_NONE;
    rs.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
    rs.lineWidth = 1.0f;
    VkPipelineMultisampleStateCreateInfo ms{};
    ms.sType = VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO;
    ms.rasterizationSamples = samples;
    VkPipelineDepthStencilStateCreateInfo ds{};
    ds.sType = VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO;
    ds.depthTestEnable = VK_TRUE;
    ds.depthWriteEnable = VK_TRUE;
    ds.depthCompareOp = VK_COMPARE_OP_LESS;
    VkPipelineColorBlendAttachmentState blend{};
    blend.colorWriteMask = 0xF;
    if (additive) {
      blend.blendEnable = VK_TRUE;
      blend.srcColorBlendFactor = VK_BLEND_FACTOR_ONE;
      blend.dstColorBlendFactor = VK_BLEND_FACTOR_ONE;
      blend.colorBlendOp = VK_BLEND_OP_ADD;
      blend.srcAlphaBlendFactor = VK_BLEND_FACTOR_ONE;
      blend.dstAlphaBlendFactor = VK_BLEND_FACTOR_ONE;
      blend.alphaBlendOp = VK_BLEND_OP_ADD;
    }
    VkPipelineColorBlendStateCreateInfo cb{};
    cb.sType = VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO;
    cb.attachmentCount = 1;
    cb.pAttachments = &blend;
    VkGraphicsPipelineCreateInfo ci{};
    ci.sType = VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO;
    ci.stageCount = 2;
    ci.pStages = stages.data();
    ci.pVertexInputState = &vi;
    ci.pInputAssemblyState = &ia;
    ci.pViewportState = &vp;
    ci.pRasterizationState = &rs;
    ci.pMultisampleState = &ms;
    ci.pDepthStencilState = &ds;
    ci.pColorBlendState = &cb;
    ci.layout = pipelineLayout.get();
    ci.renderPass = rp;
    VkPipeline p = VK_NULL_HANDLE;
    if (VkResult r = vkCreateGraphicsPipelines(dev, VK_NULL_HANDLE, 1, &ci, nullptr, &p); r != VK_SUCCESS) {
      *error = vkError("vkCreateGraphicsPipelines", r);
      return false;
    }
    *out = UniquePipeline(dev, p);
    return true;
  }

  bool uploadTexture(const Rgba8& src, std::string* error) {
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
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0,
                         nullptr, 0, nullptr, 1, &b);
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

  bool init(const std::vector<Rgba8>& texData, std::string* error) {
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

    const VkPhysicalDeviceLimits& limits = ctx.properties().limits;
    const VkSampleCountFlags counts =
        limits.framebufferColorSampleCounts & limits.framebufferDepthSampleCounts;
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
          !makeFramebuffer(basePass.get(), {baseColor[eye].view.get(), baseDepth[eye].view.get()},
                           &baseFb[eye], error)) {
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
                     VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSIENT_ATTACHMENT_BIT,
                     sc, w, h, &msaaDepth[i], error)) {
        return false;
      }
      for (int eye = 0; eye < 2; ++eye) {
        if (!makeImage(eyeFormat,
                       VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
                           VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                       VK_SAMPLE_COUNT_1_BIT, w, h, &msaaResolve[i][eye], error) ||
            !makeFramebuffer(
                msaaPass[i].get(),
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

  // Records the draws of one view; `jitter` is in pixels.
  void recordDraws(const EyeCamera& cam, const DrawList& draws, glm::vec2 jitter, float weight, bool noise) {
    const glm::mat4 shift =
        glm::translate(glm::mat4(1.0f), glm::vec3(2.0f * jitter.x / width, 2.0f * jitter.y / height, 0.0f));
    const glm::mat4 vp = shift * cam.viewProj;
    for (const DrawQuad& q : draws.quads) {
      PushConstants pc{};
      pc.mvp = vp * q.model;
      pc.tint = glm::vec4(glm::vec3(q.tint), weight);
      pc.uvST = q.uvST;
      pc.noise = noise ? glm::vec4(draws.noiseAmplitude, float(draws.noiseSeed % 16777216u), 0.0f, 0.0f)
                       : glm::vec4(0.0f);
      const uint32_t t = std::min<uint32_t>(q.texture, uint32_t(textureSets.size() - 1));
      vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipelineLayout.get(), 0, 1,
                              &textureSets[t], 0, nullptr);
      vkCmdPushConstants(cmd, pipelineLayout.get(), VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT,
                         0, sizeof(pc), &pc);
      vkCmdDraw(cmd, 6, 1, 0, 0);
    }
  }

  void beginPass(VkRenderPass rp, VkFramebuffer fb, VkPipeline pipeline, glm::vec3 clear, bool accumulate) {
    std::array<VkClearValue, 3> cv{};
    cv[0].color = accumulate ? VkClearColorValue{{0.0f, 0.0f, 0.0f, 0.0f}}
                             : VkClearColorValue{{clear.r, clear.g, clear.b, 1.0f}};
    cv[1].depthStencil = {1.0f, 0};
    VkRenderPassBeginInfo bi{};
    bi.sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO;
    bi.renderPass = rp;
    bi.framebuffer = fb;
    bi.renderArea = {{0, 0}, {uint32_t(width), uint32_t(height)}};
    bi.clearValueCount = 3;
    bi.pClearValues = cv.data();
    vkCmdBeginRenderPass(cmd, &bi, VK_SUBPASS_CONTENTS_INLINE);
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
  }

  void timestamp(uint32_t index, VkPipelineStageFlagBits stage) {
    if (timestamps) vkCmdWriteTimestamp(cmd, stage, queries.get(), index);
  }
  void readTimestamps(double* gpuMs) {
    if (!timestamps || gpuMs == nullptr) return;
    uint64_t t[2] = {0, 0};
    if (vkGetQueryPoolResults(dev, queries.get(), 0, 2, sizeof(t), t, sizeof(uint64_t),
                              VK_QUERY_RESULT_64_BIT) == VK_SUCCESS) {
      *gpuMs = double(t[1] - t[0]) * timestampPeriodNs * 1e-6;
    }
  }

  void copyToStaging(VkImage image, VkImageAspectFlags aspect, VkDeviceSize offset) {
    VkBufferImageCopy region{};
    region.bufferOffset = offset;
    region.imageSubresource = {aspect, 0, 0, 1};
    region.imageExtent = {uint32_t(width), uint32_t(height), 1};
    vkCmdCopyImageToBuffer(cmd, image, VK_IMAGE_LAYOUT_GENERAL, staging.get(), 1, &region);
  }
  void hostBarrier() {
    VkMemoryBarrier mb{};
    mb.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    mb.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    mb.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &mb, 0,
                         nullptr, 0, nullptr);
  }
  Image stagingColor8() const { return fromRgba8(static_cast<const uint8_t*>(stagingPtr), width, height); }
};

SceneRenderer::SceneRenderer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
SceneRenderer::~SceneRenderer() {
  if (impl_) vkDeviceWaitIdle(impl_->dev);
}

std::unique_ptr<SceneRenderer> SceneRenderer::create(core::VulkanContext& context, int width, int height,
                                                     const std::vector<Rgba8>& textures,
                                                     RenderOptions options, std::string* error) {
  auto impl = std::make_unique<Impl>(context, width, height, options);
  if (!impl->init(textures, error)) return nullptr;
  return std::unique_ptr<SceneRenderer>(new SceneRenderer(std::move(impl)));
}

bool SceneRenderer::renderBase(int eye, const EyeCamera& cam, const DrawList& draws, RenderedView* out,
                               double* gpuMs, std::string* error) {
  Impl& m = *impl_;
  if (!m.beginImpl(error)) return false;
  if (m.timestamps) vkCmdResetQueryPool(m.cmd, m.queries.get(), 0, 2);
  m.timestamp(0, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT);
  m.beginPass(m.basePass.get(), m.baseFb[eye].get(), m.basePipeline.get(), draws.clearColor, false);
  m.recordDraws(cam, draws, glm::vec2(0.0f), 1.0f, true);
  vkCmdEndRenderPass(m.cmd);
  m.timestamp(1, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT);
  m.globalBarrier(VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                  VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_SHADER_READ_BIT);
  const VkDeviceSize depthOffset = VkDeviceSize(m.width) * m.height * 4;
  m.copyToStaging(m.baseColor[eye].image.get(), VK_IMAGE_ASPECT_COLOR_BIT, 0);
  m.copyToStaging(m.baseDepth[eye].image.get(), VK_IMAGE_ASPECT_DEPTH_BIT, depthOffset);
  m.hostBarrier();
  if (!m.submitAndWait(error)) return false;
  m.readTimestamps(gpuMs);
  out->color = m.stagingColor8();
  out->depth.width = m.width;
  out->depth.height = m.height;
  const float* d = reinterpret_cast<const float*>(static_cast<const uint8_t*>(m.stagingPtr) + depthOffset);
  out->depth.depth.assign(d, d + size_t(m.width) * m.height);
  return true;
}

bool SceneRenderer::supportsSamples(int samples) const {
  return samples == 1 || ((samples == 2 || samples == 4) && impl_->msaaSupported[samples == 2 ? 0 : 1]);
}

bool SceneRenderer::renderMsaa(int samples, int eye, const EyeCamera& cam, const DrawList& draws, Image* out,
                               double* gpuMs, std::string* error) {
  Impl& m = *impl_;
  const int i = samples == 2 ? 0 : 1;
  if (!supportsSamples(samples)) {
    *error = std::to_string(samples) + "x MSAA is not supported by this device";
    return false;
  }
  if (!m.beginImpl(error)) return false;
  if (m.timestamps) vkCmdResetQueryPool(m.cmd, m.queries.get(), 0, 2);
  m.timestamp(0, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT);
  m.beginPass(m.msaaPass[i].get(), m.msaaFb[i][eye].get(), m.msaaPipeline[i].get(), draws.clearColor, false);
  m.recordDraws(cam, draws, glm::vec2(0.0f), 1.0f, true);
  vkCmdEndRenderPass(m.cmd);
  m.timestamp(1, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT);
  m.globalBarrier(VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
                  VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_SHADER_READ_BIT);
  m.copyToStaging(m.msaaResolve[i][eye].image.get(), VK_IMAGE_ASPECT_COLOR_BIT, 0);
  m.hostBarrier();
  if (!m.submitAndWait(error)) return false;
  m.readTimestamps(gpuMs);
  *out = m.stagingColor8();
  return true;
}

bool SceneRenderer::renderGroundTruth(const EyeCamera& cam, const DrawList& draws, int gridSize, Image* out,
                                      std::string* error) {
  Impl& m = *impl_;
  if (!m.beginImpl(error)) return false;
  m.beginPass(m.gtPass.get(), m.gtFb.get(), m.gtPipeline.get(), draws.clearColor, true);
  const float weight = 1.0f / float(gridSize * gridSize);
  // Additive accumulation only hides what is behind when the nearest surface is drawn first:
  // front to back by the view depth of each quad's centre (the scenes' quads do not intersect).
  DrawList sorted = draws;
  std::stable_sort(sorted.quads.begin(), sorted.quads.end(), [&](const DrawQuad& a, const DrawQuad& b) {
    return (cam.view * a.model[3]).z > (cam.view * b.model[3]).z;
  });
  for (int sy = 0; sy < gridSize; ++sy) {
    for (int sx = 0; sx < gridSize; ++sx) {
      if (sx + sy > 0) {
        // Each jittered sub-render needs its own depth test.
        VkClearAttachment ca{VK_IMAGE_ASPECT_DEPTH_BIT, 0, {}};
        ca.clearValue.depthStencil = {1.0f, 0};
        VkClearRect rect{{{0, 0}, {uint32_t(m.width), uint32_t(m.height)}}, 0, 1};
        vkCmdClearAttachments(m.cmd, 1, &ca, 1, &rect);
      }
      const glm::vec2 jitter((sx + 0.5f) / gridSize - 0.5f, (sy + 0.5f) / gridSize - 0.5f);
      // The background colour is accumulated as a full-screen quad behind everything.
      DrawList bg;
      DrawQuad q;
      q.model = glm::inverse(cam.viewProj) * glm::translate(glm::mat4(1.0f), glm::vec3(0.0f, 0.0f, 0.999f)) *
                glm::scale(glm::mat4(1.0f), glm::vec3(4.0f, 4.0f, 1.0f));
      q.texture = 0;
      q.tint = glm::vec4(draws.clearColor, 1.0f);
      bg.quads.push_back(q);
      m.recordDraws(cam, sorted, jitter, weight, false);
      m.recordDraws(cam, bg, jitter, weight, false);
    }
  }
  vkCmdEndRenderPass(m.cmd);
  m.globalBarrier(VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT, VK_ACCESS_TRANSFER_READ_BIT);
  m.copyToStaging(m.gtColor.image.get(), VK_IMAGE_ASPECT_COLOR_BIT, 0);
  m.hostBarrier();
  if (!m.submitAndWait(error)) return false;
  Image img(m.width, m.height);
  const size_t n = size_t(m.width) * m.height;
  if (m.accumFormat == VK_FORMAT_R32G32B32A32_SFLOAT) {
    const float* p = static_cast<const float*>(m.stagingPtr);
    for (size_t i = 0; i < n; ++i) {
      for (int c = 0; c < 3; ++c) {
        // Averaged in linear light when sRGB; the metrics compare display-encoded values.
        const float v = std::clamp(p[i * 4 + c], 0.0f, 1.0f);
        img.rgb[i * 3 + c] = m.options.srgb ? linearToSrgb(v) : v;
      }
    }
  } else {
    *error = "ground truth needs a blendable R32G32B32A32_SFLOAT target";
    return false;
  }
  *out = std::move(img);
  return true;
}

bool SceneRenderer::readOutput(int eye, Image* out, std::string* error) {
  Impl& m = *impl_;
  if (!m.beginImpl(error)) return false;
  m.globalBarrier(VK_ACCESS_MEMORY_WRITE_BIT, VK_ACCESS_TRANSFER_READ_BIT);
  m.copyToStaging(m.outputs[eye].image.get(), VK_IMAGE_ASPECT_COLOR_BIT, 0);
  m.hostBarrier();
  if (!m.submitAndWait(error)) return false;
  *out = m.stagingColor8();
  return true;
}

namespace {
core::ImageRef refOf(const GpuImage& img, int w, int h) {
  core::ImageRef r;
  r.image = img.image.get();
  r.format = img.format;
  r.extent = {uint32_t(w), uint32_t(h)};
  r.rect = {{0, 0}, {uint32_t(w), uint32_t(h)}};
  r.usage = img.usage;
  r.layout = VK_IMAGE_LAYOUT_GENERAL;
  r.finalLayout = VK_IMAGE_LAYOUT_GENERAL;
  r.mutableFormat = img.mutableFormat;
  return r;
}
}  // namespace

core::ImageRef SceneRenderer::baseColor(int eye) const {
  return refOf(impl_->baseColor[eye], impl_->width, impl_->height);
}
core::DepthRef SceneRenderer::baseDepth(int eye, float nearZ, float farZ) const {
  core::DepthRef d;
  d.image = refOf(impl_->baseDepth[eye], impl_->width, impl_->height);
  d.nearZ = nearZ;
  d.farZ = farZ;
  return d;
}
core::ImageRef SceneRenderer::msaaColor(int samples, int eye) const {
  return refOf(impl_->msaaResolve[samples == 2 ? 0 : 1][eye], impl_->width, impl_->height);
}
core::ImageRef SceneRenderer::output(int eye) const {
  return refOf(impl_->outputs[eye], impl_->width, impl_->height);
}

}  // namespace steadyxr::eval
