// The filter's own GPU objects: samplers, layouts, per-frame slots, internal images, view cache.
#include <algorithm>
#include <array>
#include <cstring>
#include <string>
#include <vector>

#include "filter_error.h"
#include "filter_impl.h"
#include "noise_estimate.h"
#include "pass_uniforms.h"

namespace steadyxr::core {

using detail::fail;
using detail::kMaxDispatches;
using detail::kQueries;
using detail::OwnedImage;
using detail::Slot;

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
  img.bytes = req.size;
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

// A buffer in host-visible, host-coherent memory of the `preferred` kind where there is one, mapped.
bool Filter::Impl::createMappedBuffer(VkDeviceSize size, VkBufferUsageFlags usage,
                                      VkMemoryPropertyFlags preferred, detail::MappedBuffer& out,
                                      void** mapped, std::string* error) {
  VkBufferCreateInfo bci{};
  bci.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
  bci.size = size;
  bci.usage = usage;
  VkBuffer buf = VK_NULL_HANDLE;
  if (vkCreateBuffer(device, &bci, nullptr, &buf) != VK_SUCCESS)
    return fail(error, "vkCreateBuffer failed"), false;
  out.buffer = Unique<VkBuffer>(device, buf);
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(device, buf, &req);
  VkMemoryAllocateInfo mai{};
  mai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
  mai.allocationSize = req.size;
  mai.memoryTypeIndex = ctx.findMemoryType(
      req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT,
      preferred);
  VkDeviceMemory mem = VK_NULL_HANDLE;
  if (mai.memoryTypeIndex == UINT32_MAX || vkAllocateMemory(device, &mai, nullptr, &mem) != VK_SUCCESS)
    return fail(error, "no host-visible memory for the filter's uniforms"), false;
  out.memory = Unique<VkDeviceMemory>(device, mem);
  vkBindBufferMemory(device, buf, mem, 0);
  if (vkMapMemory(device, mem, 0, VK_WHOLE_SIZE, 0, mapped) != VK_SUCCESS)
    return fail(error, "vkMapMemory failed"), false;  // freed memory is implicitly unmapped
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
    std::array<VkDescriptorPoolSize, 4> sizes{{
        {VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 6 * kMaxDispatches},
        {VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 4 * kMaxDispatches},
        {VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, kMaxDispatches},
        {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, kMaxDispatches},
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

    // The uniforms of every dispatch, then the frame's noise histogram and gain record (zeroed on the
    // GPU each frame). Device-local where the GPU offers host-visible video memory (resizable BAR):
    // every workgroup reads these, and reads over PCIe are slow.
    const VkDeviceSize storageAlign =
        std::max<VkDeviceSize>(props.limits.minStorageBufferOffsetAlignment, 16);
    s.noiseOffset = (uboStride * kMaxDispatches + storageAlign - 1) / storageAlign * storageAlign;
    if (!createMappedBuffer(s.noiseOffset + detail::kStorageBufferBytes,
                            VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                                VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                            VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, s.ubo, &s.mapped, error))
      return false;
    // The records copied out at the end of the frame, for the host to read in cached memory: the
    // host reading them in the uniforms' video memory, word by word over PCIe, took about 0.5 ms of
    // CPU per frame on an H100 (steadyxr-bench's cpu column, round 21).
    if (!createMappedBuffer(detail::kStorageBufferBytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                            VK_MEMORY_PROPERTY_HOST_CACHED_BIT, s.records, &s.recordsMapped, error))
      return false;
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
  if (s.noiseSampled && s.frameIndex >= noiseNextFrame) {
    noiseTracker.add(detail::mergeNoiseCopies(noiseBins(s)).data(), params.steadyFootprint,
                     params.steadyNoiseResidualOverTime, params.steadyNoiseChangeTest);
    noiseNextFrame = s.frameIndex + 1;
  }
  s.noiseSampled = false;
  if (s.gainProbed) readGainProbe(s);
  s.gainProbed = false;
  if (s.headLockedTestified)
    headLocked.noteSteadySamples(gainRecord(s)[detail::kHeadLockedCountWord], s.frameIndex);
  s.headLockedTestified = false;
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
  t.probeMs = span(0, 4);
  t.stereoMs = span(1, 2);
  t.otherMs = span(2, 3);
  t.totalMs = span(0, 3);
  t.frameIndex = s.frameIndex;
  timings = t;
}

void Filter::Impl::waitAll() {
  for (auto& s : slots) collect(s);
}

void Filter::Impl::collectFinished() {
  for (auto& s : slots)
    if (s.pending && vkGetFenceStatus(device, s.fence.get()) == VK_SUCCESS) collect(s);
}

static_assert(detail::kHeadLockedCountWord >= detail::kGainRecordWords &&
                  detail::kHeadLockedCountWord < detail::kGainCopyStrideWords,
              "the head-locked count has a word of its own on the gain record's line");

void Filter::Impl::readGainProbe(const Slot& s) {
  const uint32_t* record = gainRecord(s);
  const uint32_t samples = record[3];
  if (samples == 0 || (gainProbe && gainProbe->frameIndex > s.frameIndex)) return;  // keep the newest
  const double toMean = 1.0 / (detail::kLumaSumScale * samples);
  gainProbe = GainProbeSums{samples,
                            record[0] * toMean,
                            record[1] * toMean,
                            record[2] / (detail::kResidualSumScale * samples),
                            record[4] / (detail::kResidualSumScale * samples),
                            record[5] / (detail::kResidualSumScale * samples),
                            record[6] / (detail::kResidualSumScale * samples),
                            record[7] / (detail::kResidualSumScale * samples),
                            s.frameIndex};
}

const uint32_t* Filter::Impl::noiseBins(const Slot& s) {
  return static_cast<const uint32_t*>(s.recordsMapped);
}

const uint32_t* Filter::Impl::gainRecord(const Slot& s) {
  return noiseBins(s) +
         detail::kNoiseBufferBytes / sizeof(uint32_t);  // after the noise record (temporal.comp)
}

}  // namespace steadyxr::core
