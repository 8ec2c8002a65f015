// SceneRenderer's private state, shared by its files (renderer*.cpp): the Vulkan objects of the
// 1-sample, MSAA and ground-truth renders, and the helpers that create and record them.
#pragma once

#include "renderer.h"
#include "vk_handles.h"

#include <array>
#include <string>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

namespace steadyxr::eval {

inline constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;

// The scene shaders' push constants (shaders/scene.vert and scene.frag).
struct PushConstants {
  glm::mat4 mvp;
  glm::vec4 tint;
  glm::vec4 uvST;
  glm::vec4 noise;
};
static_assert(sizeof(PushConstants) == 112);

inline std::string vkError(const char* what, VkResult r) {
  return std::string(what) + " failed (VkResult " + std::to_string(r) + ")";
}

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

  // renderer_commands.cpp
  bool allocate(VkMemoryRequirements req, VkMemoryPropertyFlags flags, UniqueMemory* out, std::string* error,
                VkMemoryPropertyFlags preferred = 0);
  bool makeImage(VkFormat format, VkImageUsageFlags usage, VkSampleCountFlagBits samples, uint32_t w,
                 uint32_t h, GpuImage* out, std::string* error, uint32_t mipLevels = 1,
                 VkImageCreateFlags flags = 0);
  bool beginImpl(std::string* error);
  bool submitAndWait(std::string* error);
  void globalBarrier(VkAccessFlags src, VkAccessFlags dst);
  void toGeneral(VkImage image, VkImageAspectFlags aspect);
  void timestamp(uint32_t index, VkPipelineStageFlagBits stage) {
    if (timestamps) vkCmdWriteTimestamp(cmd, stage, queries.get(), index);
  }
  void readTimestamps(double* gpuMs);
  void copyToStaging(VkImage image, VkImageAspectFlags aspect, VkDeviceSize offset);
  void hostBarrier();
  Image stagingColor8() const { return fromRgba8(static_cast<const uint8_t*>(stagingPtr), width, height); }

  // renderer_pipeline.cpp
  bool makeRenderPass(VkFormat attachmentFormat, VkSampleCountFlagBits samples, bool storeDepth,
                      UniqueRenderPass* out, std::string* error);
  bool makeFramebuffer(VkRenderPass rp, std::vector<VkImageView> views, UniqueFramebuffer* out,
                       std::string* error);
  bool makePipeline(VkRenderPass rp, VkSampleCountFlagBits samples, bool additive, UniquePipeline* out,
                    std::string* error);

  // renderer_textures.cpp
  bool uploadTexture(const Rgba8& src, std::string* error);
  bool initTextures(const std::vector<Rgba8>& texData, std::string* error);

  // renderer_targets.cpp
  bool init(const std::vector<Rgba8>& texData, std::string* error);
  bool initTargets(std::string* error);

  // renderer.cpp
  void recordDraws(const EyeCamera& cam, const DrawList& draws, glm::vec2 jitter, float weight, bool noise);
  void beginPass(VkRenderPass rp, VkFramebuffer fb, VkPipeline pipeline, glm::vec3 clear, bool accumulate);
};

}  // namespace steadyxr::eval
