#include "steadyxr/core/filter.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <future>
#include <map>
#include <string>
#include <system_error>
#include <tuple>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec4.hpp>

#include "pass_uniforms.h"
#include "steadyxr/core/view_math.h"
#include "steadyxr/core/vk_handle.h"
#include "steadyxr/shaders/copy_rgba16f_spv.h"
#include "steadyxr/shaders/copy_rgba8_spv.h"
#include "steadyxr/shaders/fxaa_rgba16f_spv.h"
#include "steadyxr/shaders/fxaa_rgba8_spv.h"
#include "steadyxr/shaders/stereo_rgba16f_spv.h"
#include "steadyxr/shaders/stereo_rgba8_spv.h"
#include "steadyxr/shaders/temporal_rgba16f_spv.h"
#include "steadyxr/shaders/temporal_rgba8_spv.h"

namespace steadyxr::core {

namespace {

constexpr uint32_t kSlots = 3;
constexpr uint32_t kMaxDispatches = 8;
constexpr uint32_t kQueries = 4;
// Workgroup size (spec constants 11 and 12 in common.glsl). On llvmpipe a 32x2 group of 4x4
// blocks measured best (steadyxr-bench, 1024x1024: default 42-44 ms against 47-49 with 16x8);
// GPUs keep the 16x8 measured on the H100.
constexpr uint32_t kCpuGroupX = 32, kCpuGroupY = 2;
constexpr uint32_t kGpuGroupX = 16, kGpuGroupY = 8;
constexpr int kModeTaa = 0, kModeHmtaa = 1, kModeVtaa = 2, kModeHybrid = 3, kModeSteady = 4;  // temporal.comp

enum class Pass : uint32_t { Copy, Temporal, Stereo, Fxaa, Count };
enum OutFmt : uint32_t { kOut8 = 0, kOut16 = 1 };

// The one descriptor set layout of every pass (common.glsl): 0-3 samplers (src0, src1, depth0,
// depth1), 4-5 storage images (history out, output), 6 the uniforms, 7 a sampler (the app's
// input of this eye, whose alpha every output carries).
constexpr uint32_t kBindings = 8;
constexpr VkDescriptorType descriptorType(uint32_t binding) {
  return binding < 4 || binding == 7 ? VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER
         : binding < 6               ? VK_DESCRIPTOR_TYPE_STORAGE_IMAGE
                                     : VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
}

// The per-pipeline switches of one dispatch; they become specialisation constants (SpecKey,
// constant_id in common.glsl), not uniforms.
struct PassSwitches {
  int32_t mode = 0;         // temporal: kModeTaa ... kModeSteady
  int32_t sampleCount = 1;  // temporal: past samples (seed 003 Eq. 2)
  bool writeOutput = false;
  bool writeHistory = false;
  bool encodeSrgb = false;
  bool swapRedBlue = false;
  int32_t depthBits = 0;  // bit0: this eye's depth, bit1: the other eye's
};

// Blocks pay on a CPU device for every pass they apply to (measured with steadyxr-bench --block
// on lavapipe at 1024x1024: the copy pass 15-19 % faster, hmtaa 39-47 against 49-50 ms, the 3x3
// passes most of all), and not on a GPU, where one pixel per invocation keeps accesses coalesced.
bool blockPixels(const Params& params, const VulkanContext& ctx) {
  switch (params.invocationBlock) {
    case InvocationBlock::OnePixel:
      return false;
    case InvocationBlock::FourByFour:
      return true;
    case InvocationBlock::Auto:
      break;
  }
  return ctx.isCpuDevice();
}

bool finitePose(const Pose& p) {
  return std::isfinite(p.orientation.w) && std::isfinite(p.orientation.x) && std::isfinite(p.orientation.y) &&
         std::isfinite(p.orientation.z) && std::isfinite(p.position.x) && std::isfinite(p.position.y) &&
         std::isfinite(p.position.z) && glm::dot(p.orientation, p.orientation) > 1e-12f;
}
bool finiteFov(const Fov& f) {
  return std::isfinite(f.angleLeft) && std::isfinite(f.angleRight) && std::isfinite(f.angleUp) &&
         std::isfinite(f.angleDown) && f.angleRight > f.angleLeft && f.angleUp > f.angleDown &&
         std::abs(f.angleLeft) < 1.57f && std::abs(f.angleRight) < 1.57f && std::abs(f.angleUp) < 1.57f &&
         std::abs(f.angleDown) < 1.57f;
}

// (px, py, 1, 1/z) in a view's rect pixels -> homogeneous view-space point.
glm::mat4 pixelToView(const Fov& f, VkExtent2D size) {
  const float l = std::tan(f.angleLeft), r = std::tan(f.angleRight);
  const float u = std::tan(f.angleUp), d = std::tan(f.angleDown);
  glm::mat4 m(0.0f);  // m[col][row]
  m[0][0] = (r - l) / static_cast<float>(size.width);
  m[2][0] = l;
  m[1][1] = -(u - d) / static_cast<float>(size.height);
  m[2][1] = u;
  m[2][2] = -1.0f;
  m[3][3] = 1.0f;
  return m;
}

// View-space homogeneous point -> (qx*s, qy*s, s, s/z) with q in the rect's pixels, s = distance.
glm::mat4 viewToPixel(const Fov& f, VkExtent2D size) {
  const float l = std::tan(f.angleLeft), r = std::tan(f.angleRight);
  const float u = std::tan(f.angleUp), d = std::tan(f.angleDown);
  const float sx = static_cast<float>(size.width) / (r - l);
  const float sy = static_cast<float>(size.height) / (u - d);
  glm::mat4 m(0.0f);
  m[0][0] = sx;
  m[2][0] = sx * l;
  m[1][1] = -sy;
  m[2][1] = -sy * u;
  m[2][2] = -1.0f;
  m[3][3] = 1.0f;
  return m;
}

glm::mat4 poseMatrix(const Pose& p) {
  return glm::translate(glm::mat4(1.0f), p.position) * glm::mat4_cast(glm::normalize(p.orientation));
}

// Maps this view's pixel (+1/z) to the other image's pixel coordinates.
glm::mat4 reprojection(const Pose& from, const Fov& fromFov, VkExtent2D fromSize, const Pose& to,
                       const Fov& toFov, VkExtent2D toSize) {
  return viewToPixel(toFov, toSize) * viewFromPose(to) * poseMatrix(from) * pixelToView(fromFov, fromSize);
}

bool isSrgb(VkFormat f) {
  return f == VK_FORMAT_R8G8B8A8_SRGB || f == VK_FORMAT_B8G8R8A8_SRGB;
}
bool isBgra(VkFormat f) {
  return f == VK_FORMAT_B8G8R8A8_UNORM || f == VK_FORMAT_B8G8R8A8_SRGB;
}
// 8-bit UNORM/sRGB texels decode to [0, 1]: never NaN or Inf, so the shader need not sanitise them.
bool isUnorm8(VkFormat f) {
  return f == VK_FORMAT_R8G8B8A8_UNORM || f == VK_FORMAT_R8G8B8A8_SRGB || f == VK_FORMAT_B8G8R8A8_UNORM ||
         f == VK_FORMAT_B8G8R8A8_SRGB;
}
bool isOutputFormat(VkFormat f) {
  return f == VK_FORMAT_R8G8B8A8_UNORM || f == VK_FORMAT_R8G8B8A8_SRGB || f == VK_FORMAT_B8G8R8A8_UNORM ||
         f == VK_FORMAT_B8G8R8A8_SRGB || f == VK_FORMAT_R16G16B16A16_SFLOAT;
}
bool isDepthFormat(VkFormat f) {
  return f == VK_FORMAT_D16_UNORM || f == VK_FORMAT_D32_SFLOAT || f == VK_FORMAT_D24_UNORM_S8_UINT ||
         f == VK_FORMAT_D32_SFLOAT_S8_UINT || f == VK_FORMAT_X8_D24_UNORM_PACK32 ||
         f == VK_FORMAT_D16_UNORM_S8_UINT;
}
bool hasStencil(VkFormat f) {
  return f == VK_FORMAT_D24_UNORM_S8_UINT || f == VK_FORMAT_D32_SFLOAT_S8_UINT ||
         f == VK_FORMAT_D16_UNORM_S8_UINT;
}

void fail(std::string* error, const std::string& msg) {
  if (error) *error = msg;
}

struct OwnedImage {
  Unique<VkImage> image;
  Unique<VkDeviceMemory> memory;
  Unique<VkImageView> view;
  VkExtent2D extent{};
  VkFormat format = VK_FORMAT_UNDEFINED;
  bool initialised = false;  // transitioned from UNDEFINED to GENERAL
};

struct Slot {
  Unique<VkCommandPool> pool;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  Unique<VkFence> fence;
  Unique<VkDescriptorPool> descriptorPool;
  Unique<VkBuffer> ubo;
  Unique<VkDeviceMemory> uboMemory;
  void* mapped = nullptr;
  Unique<VkQueryPool> queries;
  bool pending = false;
  bool timed = false;
  uint64_t frameIndex = 0;
};

struct EyeState {
  std::array<OwnedImage, 2> history;  // ping-pong, RGBA16F, linear light
  std::array<OwnedImage, 2> scratch;  // intermediates for outputs without storage: [kOut8], [kOut16]
  bool valid = false;
  Pose prevPose;
  Fov prevFov;
  VkExtent2D size{};
};

using ViewKey = std::tuple<VkImage, VkFormat, uint32_t, VkImageAspectFlags>;

// Keyed by pass, output format and the specialisation constants (see common.glsl).
using SpecKey = std::array<int32_t, 13>;

struct CompiledPipeline {
  VkPipeline pipeline = VK_NULL_HANDLE;
  std::string error;
};

// Creates one compute pipeline. Touches nothing but its arguments, so it may run on a worker
// thread: vkCreateShaderModule and vkCreateComputePipelines need no external synchronisation.
CompiledPipeline compilePipeline(VkDevice device, VkPipelineLayout layout, Pass pass, OutFmt fmt,
                                 SpecKey spec) {
  const uint32_t* code = nullptr;
  size_t size = 0;
  auto pick = [&](const auto& a, const auto& b) {
    code = fmt == kOut8 ? a : b;
    size = fmt == kOut8 ? sizeof(a) : sizeof(b);
  };
  switch (pass) {
    case Pass::Copy:
      pick(copy_rgba8_spv, copy_rgba16f_spv);
      break;
    case Pass::Temporal:
      pick(temporal_rgba8_spv, temporal_rgba16f_spv);
      break;
    case Pass::Stereo:
      pick(stereo_rgba8_spv, stereo_rgba16f_spv);
      break;
    case Pass::Fxaa:
      pick(fxaa_rgba8_spv, fxaa_rgba16f_spv);
      break;
    default:
      return {VK_NULL_HANDLE, "no shader for this pass"};
  }
  VkShaderModuleCreateInfo smci{};
  smci.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
  smci.codeSize = size;
  smci.pCode = code;
  VkShaderModule module = VK_NULL_HANDLE;
  if (vkCreateShaderModule(device, &smci, nullptr, &module) != VK_SUCCESS)
    return {VK_NULL_HANDLE, "vkCreateShaderModule failed"};
  Unique<VkShaderModule> moduleOwner(device, module, vkDestroyShaderModule);
  VkComputePipelineCreateInfo cpci{};
  cpci.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
  cpci.stage = {};
  cpci.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
  cpci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  cpci.stage.module = module;
  cpci.stage.pName = "main";
  std::array<VkSpecializationMapEntry, std::tuple_size_v<SpecKey>> entries{};
  for (uint32_t i = 0; i < entries.size(); ++i) entries[i] = {i, i * 4u, 4u};  // int and VkBool32: 4 bytes
  VkSpecializationInfo si{};
  si.mapEntryCount = static_cast<uint32_t>(entries.size());
  si.pMapEntries = entries.data();
  si.dataSize = sizeof(SpecKey);
  si.pData = spec.data();
  cpci.stage.pSpecializationInfo = &si;
  cpci.layout = layout;
  VkPipeline p = VK_NULL_HANDLE;
  if (vkCreateComputePipelines(device, VK_NULL_HANDLE, 1, &cpci, nullptr, &p) != VK_SUCCESS)
    return {VK_NULL_HANDLE, "vkCreateComputePipelines failed"};
  return {p, {}};
}

// One pipeline of the cache: made, being compiled on a worker thread, or failed.
struct PipelineSlot {
  Unique<VkPipeline> pipeline;
  std::future<CompiledPipeline> pending;
  std::string error;
  VkDevice device = VK_NULL_HANDLE;

  PipelineSlot() = default;
  PipelineSlot(const PipelineSlot&) = delete;
  PipelineSlot& operator=(const PipelineSlot&) = delete;
  ~PipelineSlot() {
    if (!pending.valid()) return;
    const CompiledPipeline c = pending.get();  // joins the worker; its pipeline was never used
    if (c.pipeline) vkDestroyPipeline(device, c.pipeline, nullptr);
  }
};

// Squared spread (px^2) of where the history of a point lies, over the depths between the far
// plane (what the reprojection assumes without depth) and steadyNearestDepthM, for the eye's
// translation since the last frame: focal length in px times |translation| times the spread of 1/z.
float parallaxSpreadPx2(const Params& params, const ViewFrame& v, const EyeState& eye) {
  const float nearest = params.steadyNearestDepthM;
  if (!std::isfinite(nearest) || !(nearest > 0.0f)) return 0.0f;
  const float invFar = std::isinf(params.stereoFarDistanceM) ? 0.0f : 1.0f / params.stereoFarDistanceM;
  const float spreadInvZ = std::max(1.0f / nearest - invFar, 0.0f);
  const float focalPx =
      static_cast<float>(eye.size.width) / (std::tan(v.fov.angleRight) - std::tan(v.fov.angleLeft));
  const float e = focalPx * glm::length(v.pose.position - eye.prevPose.position) * spreadInvZ;
  return std::isfinite(e) ? std::min(e * e, 1e6f) : 1e6f;
}

}  // namespace

struct Filter::Impl {
  VulkanContext& ctx;
  VkDevice device;
  Params params;
  Params pendingParams;
  FilterOptions options;
  bool compiling = false;  // the last submit stopped at a pipeline still being compiled
  bool paramsChanged = false;
  bool resetRequested = true;
  bool timestamps = false;
  float timestampPeriodNs = 1.0f;
  VkDeviceSize uboStride = 512;

  Unique<VkSampler> sampler;         // linear: colour
  Unique<VkSampler> samplerNearest;  // depth (texelFetch only)
  Unique<VkDescriptorSetLayout> setLayout;
  Unique<VkPipelineLayout> pipelineLayout;
  std::map<std::tuple<Pass, OutFmt, SpecKey>, PipelineSlot> pipelines;
  std::array<Slot, kSlots> slots;
  std::array<EyeState, 2> eyes;
  uint32_t historyIndex = 0;  // which history image is written this frame
  OwnedImage dummy16;         // 1x1 RGBA16F: unused samplers and history writes
  OwnedImage dummy8;          // 1x1 RGBA8: unused output writes
  std::map<ViewKey, Unique<VkImageView>> views;
  uint64_t frameCounter = 0;
  std::optional<PassTimings> timings;

  explicit Impl(VulkanContext& c) : ctx(c), device(c.device()) {}
  ~Impl() { waitAll(); }

  bool init(std::string* error);
  bool createImage(OwnedImage& img, VkExtent2D extent, VkFormat format, VkImageUsageFlags usage,
                   std::string* error);
  VkPipeline pipeline(Pass pass, OutFmt fmt, const SpecKey& spec, std::string* error);
  VkImageView view(VkImage image, VkFormat format, uint32_t layer, VkImageAspectFlags aspect,
                   std::string* error);
  void collect(Slot& s);
  void waitAll();
  bool submit(const StereoFrame& frame, const StereoOutput& output, std::string* error, VkSemaphore signal);
};

bool Filter::Impl::createImage(OwnedImage& img, VkExtent2D extent, VkFormat format, VkImageUsageFlags usage,
                               std::string* error) {
  img = OwnedImage{};
  VkImageCreateInfo ici{};
  ici.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
  ici.imageType = VK_IMAGE_TYPE_2D;
  ici.format = format;
  ici.extent = {extent.width, extent.height, 1};
  ici.mipLevels = 1;
  ici.arrayLayers = 1;
  ici.samples = VK_SAMPLE_COUNT_1_BIT;
  ici.tiling = VK_IMAGE_TILING_OPTIMAL;
  ici.usage = usage;
  ici.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  VkImage image = VK_NULL_HANDLE;
  if (vkCreateImage(device, &ici, nullptr, &image) != VK_SUCCESS) {
    fail(error, "vkCreateImage failed");
    return false;
  }
  img.image = Unique<VkImage>(device, image);
  VkMemoryRequirements req;
  vkGetImageMemoryRequirements(device, image, &req);
  VkMemoryAllocateInfo mai{};
  mai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
  mai.allocationSize = req.size;
  mai.memoryTypeIndex = ctx.findMemoryType(req.memoryTypeBits, 0, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  VkDeviceMemory mem = VK_NULL_HANDLE;
  if (mai.memoryTypeIndex == UINT32_MAX || vkAllocateMemory(device, &mai, nullptr, &mem) != VK_SUCCESS) {
    fail(error, "out of device memory for an internal image");
    return false;
  }
  img.memory = Unique<VkDeviceMemory>(device, mem);
  vkBindImageMemory(device, image, mem, 0);
  VkImageViewCreateInfo vci{};
  vci.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
  vci.image = image;
  vci.viewType = VK_IMAGE_VIEW_TYPE_2D;
  vci.format = format;
  vci.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  VkImageView v = VK_NULL_HANDLE;
  if (vkCreateImageView(device, &vci, nullptr, &v) != VK_SUCCESS) {
    fail(error, "vkCreateImageView failed");
    return false;
  }
  img.view = Unique<VkImageView>(device, v);
  img.extent = extent;
  img.format = format;
  return true;
}

bool Filter::Impl::init(std::string* error) {
  uint32_t qn = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(ctx.physicalDevice(), &qn, nullptr);
  std::vector<VkQueueFamilyProperties> qf(qn);
  vkGetPhysicalDeviceQueueFamilyProperties(ctx.physicalDevice(), &qn, qf.data());
  const auto& props = ctx.properties();
  timestamps = ctx.queueFamilyIndex() < qn && qf[ctx.queueFamilyIndex()].timestampValidBits > 0 &&
               props.limits.timestampPeriod > 0.0f;
  timestampPeriodNs = props.limits.timestampPeriod;
  const VkDeviceSize align = std::max<VkDeviceSize>(props.limits.minUniformBufferOffsetAlignment, 16);
  uboStride = (sizeof(PassUniforms) + align - 1) / align * align;

  VkSamplerCreateInfo sci{};

  sci.sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO;
  sci.magFilter = sci.minFilter = VK_FILTER_LINEAR;
  sci.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
  sci.addressModeU = sci.addressModeV = sci.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
  sci.maxLod = 0.0f;
  VkSampler smp = VK_NULL_HANDLE;
  if (vkCreateSampler(device, &sci, nullptr, &smp) != VK_SUCCESS)
    return fail(error, "vkCreateSampler failed"), false;
  sampler = Unique<VkSampler>(device, smp);
  sci.magFilter = sci.minFilter = VK_FILTER_NEAREST;
  if (vkCreateSampler(device, &sci, nullptr, &smp) != VK_SUCCESS)
    return fail(error, "vkCreateSampler failed"), false;
  samplerNearest = Unique<VkSampler>(device, smp);

  std::array<VkDescriptorSetLayoutBinding, kBindings> b{};
  for (uint32_t i = 0; i < b.size(); ++i) {
    b[i].binding = i;
    b[i].descriptorCount = 1;
    b[i].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
    b[i].descriptorType = descriptorType(i);
  }
  VkDescriptorSetLayoutCreateInfo dlci{};
  dlci.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
  dlci.bindingCount = static_cast<uint32_t>(b.size());
  dlci.pBindings = b.data();
  VkDescriptorSetLayout dsl = VK_NULL_HANDLE;
  if (vkCreateDescriptorSetLayout(device, &dlci, nullptr, &dsl) != VK_SUCCESS)
    return fail(error, "vkCreateDescriptorSetLayout failed"), false;
  setLayout = Unique<VkDescriptorSetLayout>(device, dsl);
  VkPipelineLayoutCreateInfo plci{};
  plci.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
  plci.setLayoutCount = 1;
  plci.pSetLayouts = &dsl;
  VkPipelineLayout pl = VK_NULL_HANDLE;
  if (vkCreatePipelineLayout(device, &plci, nullptr, &pl) != VK_SUCCESS)
    return fail(error, "vkCreatePipelineLayout failed"), false;
  pipelineLayout = Unique<VkPipelineLayout>(device, pl);

  for (auto& s : slots) {
    VkCommandPoolCreateInfo cpci{};
    cpci.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    cpci.flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT;
    cpci.queueFamilyIndex = ctx.queueFamilyIndex();
    VkCommandPool pool = VK_NULL_HANDLE;
    if (vkCreateCommandPool(device, &cpci, nullptr, &pool) != VK_SUCCESS)
      return fail(error, "vkCreateCommandPool failed"), false;
    s.pool = Unique<VkCommandPool>(device, pool);
    VkCommandBufferAllocateInfo cbai{};
    cbai.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    cbai.commandPool = pool;
    cbai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cbai.commandBufferCount = 1;
    if (vkAllocateCommandBuffers(device, &cbai, &s.cmd) != VK_SUCCESS)
      return fail(error, "vkAllocateCommandBuffers failed"), false;
    VkFenceCreateInfo fci{};
    fci.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
    VkFence fence = VK_NULL_HANDLE;
    if (vkCreateFence(device, &fci, nullptr, &fence) != VK_SUCCESS)
      return fail(error, "vkCreateFence failed"), false;
    s.fence = Unique<VkFence>(device, fence);
    std::array<VkDescriptorPoolSize, 3> sizes{{
        {VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 5 * kMaxDispatches},
        {VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 2 * kMaxDispatches},
        {VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, kMaxDispatches},
    }};
    VkDescriptorPoolCreateInfo dpci{};
    dpci.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
    dpci.maxSets = kMaxDispatches;
    dpci.poolSizeCount = static_cast<uint32_t>(sizes.size());
    dpci.pPoolSizes = sizes.data();
    VkDescriptorPool dp = VK_NULL_HANDLE;
    if (vkCreateDescriptorPool(device, &dpci, nullptr, &dp) != VK_SUCCESS)
      return fail(error, "vkCreateDescriptorPool failed"), false;
    s.descriptorPool = Unique<VkDescriptorPool>(device, dp);

    VkBufferCreateInfo bci{};

    bci.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    bci.size = uboStride * kMaxDispatches;
    bci.usage = VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT;
    VkBuffer buf = VK_NULL_HANDLE;
    if (vkCreateBuffer(device, &bci, nullptr, &buf) != VK_SUCCESS)
      return fail(error, "vkCreateBuffer failed"), false;
    s.ubo = Unique<VkBuffer>(device, buf);
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device, buf, &req);
    VkMemoryAllocateInfo mai{};
    mai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    mai.allocationSize = req.size;
    // Device-local when the GPU offers host-visible video memory (resizable BAR): every
    // workgroup reads these, and reads over PCIe are slow.
    mai.memoryTypeIndex = ctx.findMemoryType(
        req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT,
        VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    VkDeviceMemory mem = VK_NULL_HANDLE;
    if (mai.memoryTypeIndex == UINT32_MAX || vkAllocateMemory(device, &mai, nullptr, &mem) != VK_SUCCESS)
      return fail(error, "no host-visible memory for uniforms"), false;
    s.uboMemory = Unique<VkDeviceMemory>(device, mem);
    vkBindBufferMemory(device, buf, mem, 0);
    if (vkMapMemory(device, mem, 0, VK_WHOLE_SIZE, 0, &s.mapped) != VK_SUCCESS)
      return fail(error, "vkMapMemory failed"), false;  // freed memory is implicitly unmapped
    if (timestamps) {
      VkQueryPoolCreateInfo qpci{};
      qpci.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO;
      qpci.queryType = VK_QUERY_TYPE_TIMESTAMP;
      qpci.queryCount = kQueries;
      VkQueryPool qp = VK_NULL_HANDLE;
      if (vkCreateQueryPool(device, &qpci, nullptr, &qp) != VK_SUCCESS)
        return fail(error, "vkCreateQueryPool failed"), false;
      s.queries = Unique<VkQueryPool>(device, qp);
    }
  }
  const VkImageUsageFlags dummyUsage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_STORAGE_BIT;
  return createImage(dummy16, {1, 1}, VK_FORMAT_R16G16B16A16_SFLOAT, dummyUsage, error) &&
         createImage(dummy8, {1, 1}, VK_FORMAT_R8G8B8A8_UNORM, VK_IMAGE_USAGE_STORAGE_BIT, error);
}

VkPipeline Filter::Impl::pipeline(Pass pass, OutFmt fmt, const SpecKey& spec, std::string* error) {
  PipelineSlot& slot = pipelines[{pass, fmt, spec}];
  if (slot.pipeline) return slot.pipeline.get();
  if (!slot.error.empty()) {  // failed before: not retried every frame
    fail(error, slot.error);
    return VK_NULL_HANDLE;
  }
  slot.device = device;
  if (!slot.pending.valid()) {
    if (options.compileInBackground) {
      try {
        slot.pending =
            std::async(std::launch::async, compilePipeline, device, pipelineLayout.get(), pass, fmt, spec);
      } catch (const std::system_error&) {  // no thread to be had: compile here instead
      }
    }
    if (!slot.pending.valid()) {
      std::promise<CompiledPipeline> now;
      now.set_value(compilePipeline(device, pipelineLayout.get(), pass, fmt, spec));
      slot.pending = now.get_future();
    }
  }
  if (slot.pending.wait_for(std::chrono::seconds(0)) != std::future_status::ready) {
    compiling = true;
    fail(error, "the filter's pipelines are still compiling");
    return VK_NULL_HANDLE;
  }
  CompiledPipeline c = slot.pending.get();
  if (!c.pipeline) {
    slot.error = c.error;
    fail(error, slot.error);
    return VK_NULL_HANDLE;
  }
  slot.pipeline = Unique<VkPipeline>(device, c.pipeline);
  return c.pipeline;
}

VkImageView Filter::Impl::view(VkImage image, VkFormat format, uint32_t layer, VkImageAspectFlags aspect,
                               std::string* error) {
  const ViewKey key{image, format, layer, aspect};
  if (auto it = views.find(key); it != views.end()) return it->second.get();
  VkImageViewCreateInfo vci{};
  vci.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
  vci.image = image;
  vci.viewType = VK_IMAGE_VIEW_TYPE_2D;
  vci.format = format;
  vci.subresourceRange = {aspect, 0, 1, layer, 1};
  VkImageView v = VK_NULL_HANDLE;
  if (vkCreateImageView(device, &vci, nullptr, &v) != VK_SUCCESS) {
    fail(error, "vkCreateImageView failed for an application image");
    return VK_NULL_HANDLE;
  }
  views.emplace(key, Unique<VkImageView>(device, v));
  return v;
}

void Filter::Impl::collect(Slot& s) {
  if (!s.pending) return;
  const VkFence fence = s.fence.get();
  vkWaitForFences(device, 1, &fence, VK_TRUE, UINT64_MAX);
  vkResetFences(device, 1, &fence);
  s.pending = false;
  if (!s.timed || !s.queries) return;
  std::array<uint64_t, kQueries> ts{};
  if (vkGetQueryPoolResults(device, s.queries.get(), 0, kQueries, sizeof(ts), ts.data(), sizeof(uint64_t),
                            VK_QUERY_RESULT_64_BIT) != VK_SUCCESS)
    return;
  if (timings && timings->frameIndex > s.frameIndex) return;  // keep the newest
  const double toMs = static_cast<double>(timestampPeriodNs) * 1e-6;
  auto span = [&](int a, int b) { return ts[b] >= ts[a] ? static_cast<double>(ts[b] - ts[a]) * toMs : 0.0; };
  PassTimings t;
  t.temporalMs = span(0, 1);
  t.stereoMs = span(1, 2);
  t.otherMs = span(2, 3);
  t.totalMs = span(0, 3);
  t.frameIndex = s.frameIndex;
  timings = t;
}

void Filter::Impl::waitAll() {
  for (auto& s : slots) collect(s);
}

namespace {

struct Target {
  VkImageView view = VK_NULL_HANDLE;
  OutFmt fmt = kOut8;
  OwnedImage* scratch = nullptr;  // non-null: write here, then vkCmdCopyImage to the output
  bool srgb = false;
  bool swap = false;
};

struct Binding {
  VkImageView view = VK_NULL_HANDLE;
  VkImageLayout layout = VK_IMAGE_LAYOUT_GENERAL;
  bool clean = false;  // finite by construction (our history, 8-bit input): the shader skips sanitising
};

VkImageLayout sampledLayout(VkImageLayout l, bool depth) {
  if (l == VK_IMAGE_LAYOUT_GENERAL || l == VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL) return l;
  if (depth && l == VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL) return l;
  return VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
}

bool rectInside(const ImageRef& r) {
  return r.rect.extent.width > 0 && r.rect.extent.height > 0 && r.rect.offset.x >= 0 &&
         r.rect.offset.y >= 0 &&
         static_cast<uint64_t>(r.rect.offset.x) + r.rect.extent.width <= r.extent.width &&
         static_cast<uint64_t>(r.rect.offset.y) + r.rect.extent.height <= r.extent.height &&
         r.arrayLayer < std::max(r.arrayLayerCount, 1u);
}

bool sameExtent(VkExtent2D a, VkExtent2D b) {
  return a.width == b.width && a.height == b.height;
}

DepthToInvZ depthToInvZ(const DepthRef& d) {
  // 1/z is linear in normalised depth: 1/z = 1/nearZ + n * (1/farZ - 1/nearZ); farZ may be +inf.
  const float invNear = 1.0f / d.nearZ;
  const float invFar = std::isinf(d.farZ) ? 0.0f : 1.0f / d.farZ;
  const float range = d.maxDepth - d.minDepth;
  return {invNear, invFar - invNear, d.minDepth, range != 0.0f ? 1.0f / range : 1.0f};
}

bool validDepth(const DepthRef& d) {
  return isDepthFormat(d.image.format) && std::isfinite(d.nearZ) && d.nearZ > 0.0f && d.farZ > 0.0f &&
         !std::isnan(d.farZ) && d.nearZ != d.farZ && std::isfinite(d.minDepth) && std::isfinite(d.maxDepth);
}

}  // namespace

bool Filter::Impl::submit(const StereoFrame& frame, const StereoOutput& output, std::string* error,
                          VkSemaphore signal) {
  compiling = false;
  if (paramsChanged) {
    if (pendingParams.temporal != params.temporal) resetRequested = true;
    params = pendingParams;
    paramsChanged = false;
  }
  const uint32_t n = frame.viewCount;
  if (n < 1 || n > 2) return fail(error, "viewCount must be 1 or 2"), false;
  std::array<bool, 2> hasDepth{false, false};
  for (uint32_t e = 0; e < n; ++e) {
    const ViewFrame& v = frame.views[e];
    const ImageRef& out = output.views[e];
    if (!v.color.image || !out.image) return fail(error, "missing input or output image"), false;
    if (!rectInside(v.color) || !rectInside(out)) return fail(error, "image rect outside the image"), false;
    if (!sameExtent(v.color.rect.extent, out.rect.extent))
      return fail(error, "output rect size differs from the input rect size"), false;
    if (v.color.format == VK_FORMAT_UNDEFINED || isDepthFormat(v.color.format))
      return fail(error, "unsupported input colour format"), false;
    if (v.color.usage != 0 && !(v.color.usage & VK_IMAGE_USAGE_SAMPLED_BIT))
      return fail(error, "input image lacks SAMPLED usage"), false;
    if (!isOutputFormat(out.format)) return fail(error, "unsupported output format"), false;
    if (v.depth) {
      if (!v.depth->image.image || !validDepth(*v.depth) || !rectInside(v.depth->image) ||
          !sameExtent(v.depth->image.rect.extent, v.color.rect.extent))
        return fail(error, "invalid depth image (format, range or rect)"), false;
      hasDepth[e] = true;
    }
  }
  const TemporalMethod method = params.temporal;
  const bool temporal = method == TemporalMethod::Taa || method == TemporalMethod::Hmtaa ||
                        method == TemporalMethod::Vtaa || method == TemporalMethod::Hybrid ||
                        method == TemporalMethod::Steady;
  const bool fxaa = method == TemporalMethod::Fxaa;
  const bool stereo = params.stereo && n == 2;
  const bool stage1 = temporal || fxaa || !stereo;  // `none` + stereo reads the inputs directly

  // Internal images follow the rect size; a size change drops the history.
  for (uint32_t e = 0; e < n; ++e) {
    EyeState& eye = eyes[e];
    const VkExtent2D size = frame.views[e].color.rect.extent;
    if (!eye.history[0].image || !sameExtent(eye.size, size)) {
      waitAll();
      const VkImageUsageFlags usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_STORAGE_BIT;
      for (auto& h : eye.history) {
        if (!createImage(h, size, VK_FORMAT_R16G16B16A16_SFLOAT, usage, error)) return false;
      }
      for (auto& sc : eye.scratch) sc = OwnedImage{};
      eye.size = size;
      eye.valid = false;
    }
  }
  if (frame.reset || resetRequested) {
    for (auto& eye : eyes) eye.valid = false;
    resetRequested = false;
  }
  std::array<bool, 2> poseOk{false, false};
  for (uint32_t e = 0; e < n; ++e) {
    const ViewFrame& v = frame.views[e];
    EyeState& eye = eyes[e];
    poseOk[e] = finitePose(v.pose) && finiteFov(v.fov);
    if (!poseOk[e]) {
      eye.valid = false;
    } else if (eye.valid) {
      const float angle = angleBetweenDeg(eye.prevPose.orientation, v.pose.orientation);
      const float dist = glm::length(eye.prevPose.position - v.pose.position);
      if (!(angle <= params.resetAngleDeg) || !(dist <= params.resetTranslationM)) eye.valid = false;
    }
  }

  // Output targets: direct storage writes where possible, else an intermediate and a copy.
  std::array<Target, 2> targets{};
  for (uint32_t e = 0; e < n; ++e) {
    const ImageRef& out = output.views[e];
    Target& t = targets[e];
    const bool is16 = out.format == VK_FORMAT_R16G16B16A16_SFLOAT;
    const VkFormat viewFormat = is16 ? VK_FORMAT_R16G16B16A16_SFLOAT : VK_FORMAT_R8G8B8A8_UNORM;
    t.fmt = is16 ? kOut16 : kOut8;
    t.srgb = isSrgb(out.format);
    t.swap = isBgra(out.format);
    VkFormatProperties fp;
    vkGetPhysicalDeviceFormatProperties(ctx.physicalDevice(), viewFormat, &fp);
    const bool storageOk = (fp.optimalTilingFeatures & VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT) != 0;
    if ((out.usage & VK_IMAGE_USAGE_STORAGE_BIT) && storageOk &&
        (out.format == viewFormat || out.mutableFormat)) {
      t.view = view(out.image, viewFormat, out.arrayLayer, VK_IMAGE_ASPECT_COLOR_BIT, error);
      if (!t.view) return false;
    } else if (out.usage & VK_IMAGE_USAGE_TRANSFER_DST_BIT) {
      OwnedImage& sc = eyes[e].scratch[t.fmt];
      if (!sc.image) {
        const VkImageUsageFlags usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
        if (!createImage(sc, out.rect.extent, viewFormat, usage, error)) return false;
      }
      t.scratch = &sc;
      t.view = sc.view.get();
    } else {
      return fail(error,
                  "output image needs STORAGE (storage-capable or mutable format) or TRANSFER_DST usage"),
             false;
    }
  }
  std::array<Binding, 2> inputs{}, depths{};
  for (uint32_t e = 0; e < n; ++e) {
    const ImageRef& in = frame.views[e].color;
    inputs[e] = {view(in.image, in.format, in.arrayLayer, VK_IMAGE_ASPECT_COLOR_BIT, error),
                 sampledLayout(in.layout, false), isUnorm8(in.format)};
    if (!inputs[e].view) return false;
    if (hasDepth[e]) {
      const ImageRef& d = frame.views[e].depth->image;
      depths[e] = {view(d.image, d.format, d.arrayLayer, VK_IMAGE_ASPECT_DEPTH_BIT, error),
                   sampledLayout(d.layout, true)};
      if (!depths[e].view) return false;
    }
  }

  Slot& s = slots[frameCounter % kSlots];
  collect(s);  // waits only for this slot's frame from kSlots frames ago
  vkResetDescriptorPool(device, s.descriptorPool.get(), 0);
  vkResetCommandPool(device, s.pool.get(), 0);
  const VkCommandBuffer cmd = s.cmd;
  VkCommandBufferBeginInfo cbbi{};
  cbbi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  cbbi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  vkBeginCommandBuffer(cmd, &cbbi);
  if (s.queries) vkCmdResetQueryPool(cmd, s.queries.get(), 0, kQueries);

  // Layout transitions in, and back to finalLayout at the end; one barrier per distinct image.
  std::vector<VkImageMemoryBarrier> pre, post;
  std::vector<VkImage> seen;
  auto addApp = [&](const ImageRef& r, VkImageLayout work, VkImageAspectFlags aspect) {
    if (std::find(seen.begin(), seen.end(), r.image) != seen.end()) return;
    seen.push_back(r.image);
    VkImageLayout final = r.finalLayout.value_or(r.layout);
    if (final == VK_IMAGE_LAYOUT_UNDEFINED || final == VK_IMAGE_LAYOUT_PREINITIALIZED) final = work;
    VkImageMemoryBarrier b{};
    b.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = r.image;
    b.subresourceRange = {aspect, 0, 1, 0, std::max(r.arrayLayerCount, 1u)};
    b.srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT;
    b.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
    b.oldLayout = r.layout;
    b.newLayout = work;
    pre.push_back(b);
    b.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
    b.dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
    b.oldLayout = work;
    b.newLayout = final;
    post.push_back(b);
  };
  for (uint32_t e = 0; e < n; ++e) {
    const ImageRef& out = output.views[e];
    addApp(out, targets[e].scratch ? VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL : VK_IMAGE_LAYOUT_GENERAL,
           VK_IMAGE_ASPECT_COLOR_BIT);
  }
  for (uint32_t e = 0; e < n; ++e) {
    addApp(frame.views[e].color, inputs[e].layout, VK_IMAGE_ASPECT_COLOR_BIT);
    if (hasDepth[e]) {
      const VkFormat f = frame.views[e].depth->image.format;
      addApp(frame.views[e].depth->image, depths[e].layout,
             VK_IMAGE_ASPECT_DEPTH_BIT | (hasStencil(f) ? VK_IMAGE_ASPECT_STENCIL_BIT : 0));
    }
  }
  auto addOwned = [&](OwnedImage& img) {
    if (!img.image || img.initialised) return;
    VkImageMemoryBarrier b{};
    b.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = img.image.get();
    b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    b.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
    b.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    b.newLayout = VK_IMAGE_LAYOUT_GENERAL;  // internal images always stay GENERAL
    pre.push_back(b);
    img.initialised = true;
  };
  addOwned(dummy16);
  addOwned(dummy8);
  for (uint32_t e = 0; e < n; ++e) {
    for (auto& h : eyes[e].history) addOwned(h);
    for (auto& sc : eyes[e].scratch) addOwned(sc);
  }
  // Earlier frames' writes to the internal images (history) before this frame reads/overwrites them.
  VkMemoryBarrier mem{};
  mem.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
  mem.srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT;
  mem.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT |
                      VK_ACCESS_TRANSFER_WRITE_BIT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT,
                       VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 1, &mem, 0,
                       nullptr, static_cast<uint32_t>(pre.size()), pre.data());
  if (s.queries) vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, s.queries.get(), 0);

  uint32_t dispatchIndex = 0;
  VkPipeline bound = VK_NULL_HANDLE;
  const Binding dummySampled{dummy16.view.get(), VK_IMAGE_LAYOUT_GENERAL};
  const bool cpuDevice = ctx.isCpuDevice();
  const uint32_t groupX = cpuDevice ? kCpuGroupX : kGpuGroupX;
  const uint32_t groupY = cpuDevice ? kCpuGroupY : kGpuGroupY;
  auto dispatch = [&](Pass pass, OutFmt fmt, const PassUniforms& u, const PassSwitches& sw, Binding src0,
                      Binding src1, Binding d0, Binding d1, Binding appIn, VkImageView histOut,
                      VkImageView out) -> bool {
    const bool writeOut = sw.writeOutput;
    const bool blocked = pass != Pass::Fxaa && blockPixels(params, ctx);  // fxaa's reads follow the edges
    const bool jittered = params.jitteredInput || u.jitterPx.x != 0.0f || u.jitterPx.y != 0.0f;
    const SpecKey spec{pass == Pass::Temporal ? sw.mode : 0,
                       pass == Pass::Temporal ? std::max(sw.sampleCount, 1) : 1,
                       writeOut ? 1 : 0,
                       sw.writeHistory ? 1 : 0,
                       writeOut && sw.encodeSrgb ? 1 : 0,
                       writeOut && sw.swapRedBlue ? 1 : 0,
                       sw.depthBits,
                       (src0.clean ? 1 : 0) | (src1.clean ? 2 : 0),
                       pass == Pass::Temporal && jittered ? 1 : 0,
                       pass == Pass::Temporal && params.historyFilter == HistoryFilter::CatmullRom ? 1 : 0,
                       blocked ? 1 : 0,
                       static_cast<int32_t>(groupX),
                       static_cast<int32_t>(groupY)};
    const VkPipeline p = pipeline(pass, fmt, spec, error);
    if (!p && compiling) return true;  // record nothing, but go on: every pipeline of the frame starts
    if (!p || dispatchIndex >= kMaxDispatches) return false;
    const VkDeviceSize offset = uboStride * dispatchIndex++;
    std::memcpy(static_cast<char*>(s.mapped) + offset, &u, sizeof(u));
    VkDescriptorSetAllocateInfo dsai{};
    dsai.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
    dsai.descriptorPool = s.descriptorPool.get();
    dsai.descriptorSetCount = 1;
    const VkDescriptorSetLayout dsl = setLayout.get();
    dsai.pSetLayouts = &dsl;
    VkDescriptorSet set = VK_NULL_HANDLE;
    if (vkAllocateDescriptorSets(device, &dsai, &set) != VK_SUCCESS)
      return fail(error, "descriptor pool"), false;
    std::array<VkDescriptorImageInfo, kBindings> ii{{
        {sampler.get(), src0.view ? src0.view : dummySampled.view,
         src0.view ? src0.layout : dummySampled.layout},
        {sampler.get(), src1.view ? src1.view : dummySampled.view,
         src1.view ? src1.layout : dummySampled.layout},
        {samplerNearest.get(), d0.view ? d0.view : dummySampled.view,
         d0.view ? d0.layout : dummySampled.layout},
        {samplerNearest.get(), d1.view ? d1.view : dummySampled.view,
         d1.view ? d1.layout : dummySampled.layout},
        {VK_NULL_HANDLE, histOut ? histOut : dummy16.view.get(), VK_IMAGE_LAYOUT_GENERAL},
        {VK_NULL_HANDLE, out ? out : (fmt == kOut8 ? dummy8.view.get() : dummy16.view.get()),
         VK_IMAGE_LAYOUT_GENERAL},
        {},  // 6: the uniform buffer
        {samplerNearest.get(), appIn.view ? appIn.view : dummySampled.view,
         appIn.view ? appIn.layout : dummySampled.layout},
    }};
    const VkDescriptorBufferInfo bi{s.ubo.get(), offset, sizeof(PassUniforms)};
    std::array<VkWriteDescriptorSet, kBindings> w{};
    for (uint32_t i = 0; i < w.size(); ++i) {
      w[i] = {};
      w[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
      w[i].dstSet = set;
      w[i].dstBinding = i;
      w[i].descriptorCount = 1;
      w[i].descriptorType = descriptorType(i);
      if (w[i].descriptorType == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER)
        w[i].pBufferInfo = &bi;
      else
        w[i].pImageInfo = &ii[i];
    }
    vkUpdateDescriptorSets(device, static_cast<uint32_t>(w.size()), w.data(), 0, nullptr);
    if (p != bound) vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p);
    bound = p;
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipelineLayout.get(), 0, 1, &set, 0,
                            nullptr);
    // blocked: each invocation handles 4x4 pixels (kBlockW x kBlockH)
    const uint32_t gx = blocked ? 4 * groupX : groupX;
    const uint32_t gy = blocked ? 4 * groupY : groupY;
    vkCmdDispatch(cmd, (static_cast<uint32_t>(u.src0Size.x) + gx - 1) / gx,
                  (static_cast<uint32_t>(u.src0Size.y) + gy - 1) / gy, 1);
    return true;
  };

  const float invFar = std::isinf(params.stereoFarDistanceM) ? 0.0f : 1.0f / params.stereoFarDistanceM;
  const float h = frame.headSpeedDegPerSec;
  const float shape = std::isfinite(h) && h <= params.hMaxDegPerSec
                          ? globalWeightA(h, params.hMaxDegPerSec, 0.0f)
                          : 1.0f;  // seed 003 Eq. 4 with w_min = 0: S
  auto baseUniforms = [&](uint32_t e) {
    PassUniforms u{};
    const ImageRef& in = frame.views[e].color;
    u.src0Offset = {in.rect.offset.x, in.rect.offset.y};
    u.src0Size = {in.rect.extent.width, in.rect.extent.height};
    u.src0InvExtent = {1.0f / static_cast<float>(in.extent.width),
                       1.0f / static_cast<float>(in.extent.height)};
    const ImageRef& out = output.views[e];
    if (!targets[e].scratch) u.outOffset = {out.rect.offset.x, out.rect.offset.y};
    u.appInputOffset = {in.rect.offset.x, in.rect.offset.y};
    u.taaAlpha = params.taaAlpha;
    u.clipGamma = params.taaClipGamma;
    u.alphaMin = params.vtaaAlphaMin;
    u.shapeS = shape;
    u.wMin = params.wMin;
    u.wLowerBound = params.wLowerBound;
    u.stereoDepthTolerance = params.stereoDepthTolerance;
    u.fallbackInvZ = invFar;
    if (hasDepth[e]) {
      u.depth0 = depthToInvZ(*frame.views[e].depth);
      const auto& r = frame.views[e].depth->image.rect;
      u.depth0Offset = {r.offset.x, r.offset.y};
    }
    return u;
  };
  auto baseSwitches = [&](uint32_t e) {
    PassSwitches sw;
    sw.encodeSrgb = targets[e].srgb;
    sw.swapRedBlue = targets[e].swap;
    sw.depthBits = hasDepth[e] ? 1 : 0;
    return sw;
  };
  const uint32_t cur = historyIndex, prev = historyIndex ^ 1u;
  auto historyBinding = [&](uint32_t e, uint32_t i) {
    return Binding{eyes[e].history[i].view.get(), VK_IMAGE_LAYOUT_GENERAL, true};
  };
  auto historySize = [&](uint32_t e) { return glm::ivec2(eyes[e].size.width, eyes[e].size.height); };
  auto historyInv = [&](uint32_t e) {
    return glm::vec2(1.0f / static_cast<float>(eyes[e].size.width),
                     1.0f / static_cast<float>(eyes[e].size.height));
  };

  bool ok = true;
  if (stage1) {
    for (uint32_t e = 0; e < n && ok; ++e) {
      PassUniforms u = baseUniforms(e);
      PassSwitches sw = baseSwitches(e);
      const VkImageView out = stereo ? VK_NULL_HANDLE : targets[e].view;
      const OutFmt fmt = stereo ? kOut8 : targets[e].fmt;
      sw.writeOutput = !stereo;
      sw.writeHistory = temporal || stereo;
      const VkImageView histOut = sw.writeHistory ? eyes[e].history[cur].view.get() : VK_NULL_HANDLE;
      if (temporal) {
        const ViewFrame& v = frame.views[e];
        const EyeState& eye = eyes[e];
        u.src1Offset = {0, 0};
        u.src1Size = historySize(e);
        u.src1InvExtent = historyInv(e);
        u.historyValid = eye.valid ? 1 : 0;
        const bool steady = method == TemporalMethod::Steady;
        const bool interpolated = method == TemporalMethod::Hmtaa || method == TemporalMethod::Hybrid ||
                                  (steady && params.steadyInterpolated);
        const uint32_t count = interpolated && !steady ? params.sampleCount : 1u;
        std::array<float, Params::kMaxSamples> w{};
        sampleWeightsW(params.sampleD.data(), count, w.data());
        for (uint32_t i = 0; i < count && eye.valid; ++i) {
          const Pose at =
              interpolated ? interpolatePose(eye.prevPose, v.pose, params.sampleD[i]) : eye.prevPose;
          u.reproj[i] = reprojection(v.pose, v.fov, eye.size, at, eye.prevFov, eye.size);
          u.sampleWeights[static_cast<int>(i)] = w[i];
        }
        const int mode = method == TemporalMethod::Taa     ? kModeTaa
                         : method == TemporalMethod::Hmtaa ? kModeHmtaa
                         : method == TemporalMethod::Vtaa  ? kModeVtaa
                         : steady                          ? kModeSteady
                                                           : kModeHybrid;
        if (steady) {  // uniforms of the steady mode (common.glsl, PassParams)
          u.clipGamma = params.steadyClipGamma;
          u.steadyAlphaFloor = params.steadyAlphaFloor;
          u.steadyConfidence = params.steadyConfidence ? 1.0f : 0.0f;
          u.steadyClipRejects = params.steadyClipRejects ? 1.0f : 0.0f;
          u.steadyInvBlurBudgetPx2 =
              params.steadyBlurBudgetPx2 > 0.0f ? 1.0f / params.steadyBlurBudgetPx2 : 0.0f;
          u.steadyFootprint = params.steadyFootprint;
        }
        sw.mode = mode;
        sw.sampleCount = static_cast<int32_t>(count);
        u.jitterPx = v.jitterPx;
        if (!std::isfinite(u.jitterPx.x) || !std::isfinite(u.jitterPx.y) || std::abs(u.jitterPx.x) > 1.0f ||
            std::abs(u.jitterPx.y) > 1.0f)
          u.jitterPx = glm::vec2(0.0f);  // sub-pixel only; anything else is a caller bug: ignore it
        if (steady && eye.valid) u.parallaxSpreadPx2 = hasDepth[e] ? 0.0f : parallaxSpreadPx2(params, v, eye);
        ok = dispatch(Pass::Temporal, fmt, u, sw, inputs[e], historyBinding(e, prev), depths[e], {},
                      inputs[e], histOut, out);
      } else {
        ok = dispatch(fxaa ? Pass::Fxaa : Pass::Copy, fmt, u, sw, inputs[e], {}, {}, {}, inputs[e], histOut,
                      out);
      }
    }
  }
  if (ok && stereo && stage1) {
    VkMemoryBarrier m{};
    m.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    m.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
    m.dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0,
                         1, &m, 0, nullptr, 0, nullptr);
  }
  if (s.queries) vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, s.queries.get(), 1);
  if (ok && stereo) {
    for (uint32_t e = 0; e < 2 && ok; ++e) {
      const uint32_t o = 1 - e;
      PassUniforms u = baseUniforms(e);
      PassSwitches sw = baseSwitches(e);
      const ImageRef& inO = frame.views[o].color;
      Binding src0 = inputs[e], src1 = inputs[o];
      u.src1Offset = {inO.rect.offset.x, inO.rect.offset.y};
      u.src1Size = {inO.rect.extent.width, inO.rect.extent.height};
      u.src1InvExtent = {1.0f / static_cast<float>(inO.extent.width),
                         1.0f / static_cast<float>(inO.extent.height)};
      if (stage1) {  // the temporal/FXAA result sits in this frame's history image
        src0 = historyBinding(e, cur);
        src1 = historyBinding(o, cur);
        u.src0Offset = {0, 0};
        u.src0Size = historySize(e);
        u.src0InvExtent = historyInv(e);
        u.src1Offset = {0, 0};
        u.src1Size = historySize(o);
        u.src1InvExtent = historyInv(o);
      }
      if (poseOk[e] && poseOk[o]) {
        const ViewFrame& ve = frame.views[e];
        const ViewFrame& vo = frame.views[o];
        u.reproj[0] =
            reprojection(ve.pose, ve.fov, ve.color.rect.extent, vo.pose, vo.fov, vo.color.rect.extent);
      }  // else all zero: every reprojection fails and the eye is shown as is
      if (hasDepth[o]) {
        u.depth1 = depthToInvZ(*frame.views[o].depth);
        const auto& r = frame.views[o].depth->image.rect;
        u.depth1Offset = {r.offset.x, r.offset.y};
        sw.depthBits |= 2;
      }
      u.stereoBetaMin = params.stereoBetaMin;
      sw.writeOutput = true;
      ok = dispatch(Pass::Stereo, targets[e].fmt, u, sw, src0, src1, depths[e], depths[o], inputs[e],
                    VK_NULL_HANDLE, targets[e].view);
    }
  }
  if (s.queries) vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, s.queries.get(), 2);
  std::vector<VkImageMemoryBarrier> toCopy;
  for (uint32_t e = 0; e < n; ++e) {
    if (!targets[e].scratch) continue;
    VkImageMemoryBarrier b{};
    b.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = targets[e].scratch->image.get();
    b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    b.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
    b.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
    b.oldLayout = VK_IMAGE_LAYOUT_GENERAL;
    b.newLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    toCopy.push_back(b);
    b.srcAccessMask = VK_ACCESS_TRANSFER_READ_BIT;  // back to GENERAL for the next frame's writes
    b.dstAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
    std::swap(b.oldLayout, b.newLayout);
    post.push_back(b);
  }
  if (!toCopy.empty()) {  // always: post[] turns these layouts back
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0,
                         nullptr, 0, nullptr, static_cast<uint32_t>(toCopy.size()), toCopy.data());
    for (uint32_t e = 0; e < n && ok; ++e) {
      if (!targets[e].scratch) continue;
      const ImageRef& out = output.views[e];
      VkImageCopy region{};
      region.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
      region.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, out.arrayLayer, 1};
      region.dstOffset = {out.rect.offset.x, out.rect.offset.y, 0};
      region.extent = {out.rect.extent.width, out.rect.extent.height, 1};
      vkCmdCopyImage(cmd, targets[e].scratch->image.get(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, out.image,
                     VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
    }
  }
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                       VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 0, nullptr, 0, nullptr,
                       static_cast<uint32_t>(post.size()), post.data());
  if (s.queries) vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, s.queries.get(), 3);
  if (compiling) ok = false;  // no dispatch was recorded for the passes still compiling
  if (vkEndCommandBuffer(cmd) != VK_SUCCESS) {
    fail(error, "vkEndCommandBuffer failed");
    return false;  // nothing was submitted; the slot stays free
  }
  // Even a failed recording is submitted when it holds the layout transitions, so the images end in
  // finalLayout; a failed dispatch only leaves the output unwritten.
  VkSubmitInfo si{};
  si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cmd;
  if (signal) {
    si.signalSemaphoreCount = 1;
    si.pSignalSemaphores = &signal;
  }
  if (VkResult r = vkQueueSubmit(ctx.queue(), 1, &si, s.fence.get()); r != VK_SUCCESS) {
    return fail(error, "vkQueueSubmit failed: " + std::to_string(r)), false;
  }
  s.pending = true;
  s.timed = static_cast<bool>(s.queries);
  s.frameIndex = frameCounter++;
  if (!ok) {
    for (auto& eye : eyes) eye.valid = false;
    if (error && error->empty()) *error = "recording the filter commands failed";
    return false;
  }
  for (uint32_t e = 0; e < n; ++e) {
    EyeState& eye = eyes[e];
    eye.valid = temporal && poseOk[e];
    if (poseOk[e]) {
      eye.prevPose = frame.views[e].pose;
      eye.prevFov = frame.views[e].fov;
    }
  }
  historyIndex ^= 1u;
  return true;
}

Filter::Filter(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Filter::~Filter() = default;

std::unique_ptr<Filter> Filter::create(VulkanContext& context, const Params& params, std::string* error,
                                       const FilterOptions& options) {
  Params p;
  if (std::string msg = validate(params, &p); !msg.empty()) {
    if (error) *error = msg;
    return nullptr;
  }
  auto impl = std::make_unique<Impl>(context);
  impl->params = p;
  impl->pendingParams = p;
  impl->options = options;
  if (!impl->init(error)) return nullptr;
  return std::unique_ptr<Filter>(new Filter(std::move(impl)));
}

bool Filter::compiling() const {
  return impl_->compiling;
}

bool Filter::submit(const StereoFrame& frame, const StereoOutput& output, std::string* error,
                    VkSemaphore signalSemaphore) {
  if (error) error->clear();
  return impl_->submit(frame, output, error, signalSemaphore);
}

void Filter::setParams(const Params& params) {
  validate(params, &impl_->pendingParams);  // bad fields fall back to their defaults
  impl_->paramsChanged = true;
}

const Params& Filter::params() const {
  return impl_->paramsChanged ? impl_->pendingParams : impl_->params;
}
void Filter::reset() {
  impl_->resetRequested = true;
}
void Filter::waitIdle() {
  impl_->waitAll();
}
std::optional<PassTimings> Filter::lastTimings() const {
  return impl_->timings;
}

void Filter::forgetImage(VkImage image) {
  bool any = false;
  for (const auto& [key, v] : impl_->views) any = any || std::get<0>(key) == image;
  if (!any) return;
  impl_->waitAll();  // a pending frame may still use the view
  std::erase_if(impl_->views, [&](const auto& kv) { return std::get<0>(kv.first) == image; });
}

}  // namespace steadyxr::core
