// Recording one frame's commands: the slot, layout transitions, each pass's dispatch, the copy out.
#include <algorithm>
#include <array>
#include <cstring>
#include <string>
#include <vector>

#include "filter_error.h"
#include "filter_formats.h"
#include "filter_impl.h"
#include "noise_estimate.h"

namespace steadyxr::core {

using detail::Binding;
using detail::descriptorType;
using detail::fail;
using detail::FramePlan;
using detail::hasStencil;
using detail::kBindings;
using detail::kCpuGroupX;
using detail::kCpuGroupY;
using detail::kGpuGroupX;
using detail::kGpuGroupY;
using detail::kMaxDispatches;
using detail::kOut8;
using detail::kQueries;
using detail::kSlots;
using detail::OwnedImage;
using detail::Pass;
using detail::PassDispatch;
using detail::PassIo;
using detail::passSpecKey;
using detail::Slot;

// Blocks pay on a CPU device for every pass they apply to (measured with steadyxr-bench --block
// on lavapipe at 1024x1024: the copy pass 15-19 % faster, hmtaa 39-47 against 49-50 ms, the 3x3
// passes most of all), and not on a GPU, where one pixel per invocation keeps accesses coalesced.
bool Filter::Impl::blocksPixels() const {
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

Slot& Filter::Impl::beginRecording() {
  Slot& s = slots[frameCounter % kSlots];
  collect(s);  // waits only for this slot's frame from kSlots frames ago
  vkResetDescriptorPool(device, s.descriptorPool.get(), 0);
  vkResetCommandPool(device, s.pool.get(), 0);
  VkCommandBufferBeginInfo cbbi{};
  cbbi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  cbbi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  vkBeginCommandBuffer(s.cmd, &cbbi);
  if (s.queries) vkCmdResetQueryPool(s.cmd, s.queries.get(), 0, kQueries);
  return s;
}

void Filter::Impl::timestamp(const Slot& s, uint32_t query) {
  if (s.queries) vkCmdWriteTimestamp(s.cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, s.queries.get(), query);
}

std::vector<VkImageMemoryBarrier> Filter::Impl::transitionIn(VkCommandBuffer cmd, const StereoFrame& frame,
                                                             const StereoOutput& output,
                                                             const FramePlan& plan) {
  const uint32_t n = plan.viewCount;
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
    addApp(out, plan.targets[e].scratch ? VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL : VK_IMAGE_LAYOUT_GENERAL,
           VK_IMAGE_ASPECT_COLOR_BIT);
  }
  for (uint32_t e = 0; e < n; ++e) {
    addApp(frame.views[e].color, plan.inputs[e].layout, VK_IMAGE_ASPECT_COLOR_BIT);
    if (plan.hasDepth[e]) {
      const VkFormat f = frame.views[e].depth->image.format;
      addApp(frame.views[e].depth->image, plan.depths[e].layout,
             VK_IMAGE_ASPECT_DEPTH_BIT | (hasStencil(f) ? VK_IMAGE_ASPECT_STENCIL_BIT : 0));
    }
  }
  std::vector<VkImage> toClear;
  auto addOwned = [&](OwnedImage& img) {
    if (!img.image || img.initialised) return;
    if (img.clearOnInit) toClear.push_back(img.image.get());
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
    for (auto& sh : eyes[e].shown) addOwned(sh);
    addOwned(eyes[e].headLockedRecord);
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
  if (!toClear.empty()) {  // once per new image: the passes' bilinear taps may reach past the rect
    const VkClearColorValue zero{};
    const VkImageSubresourceRange all{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    for (VkImage image : toClear) vkCmdClearColorImage(cmd, image, VK_IMAGE_LAYOUT_GENERAL, &zero, 1, &all);
    mem.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    mem.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 1,
                         &mem, 0, nullptr, 0, nullptr);
  }
  return post;
}

detail::SpecKey Filter::Impl::specKeyOf(const PassDispatch& d) const {
  const bool cpuDevice = ctx.isCpuDevice();
  const uint32_t groupX = cpuDevice ? kCpuGroupX : kGpuGroupX;
  const uint32_t groupY = cpuDevice ? kCpuGroupY : kGpuGroupY;
  // fxaa's reads follow the edges; the probe has blocks of its own on every device (probeBlockPx).
  const bool blocked = d.switches.probe || (d.pass != Pass::Fxaa && blocksPixels());
  return passSpecKey(d, params, blocked, groupX, groupY);
}

bool Filter::Impl::record(Recording& rec, const PassDispatch& d, std::string* error) {
  Slot& s = rec.slot;
  const VkCommandBuffer cmd = s.cmd;
  const bool cpuDevice = ctx.isCpuDevice();
  const uint32_t groupX = cpuDevice ? kCpuGroupX : kGpuGroupX;
  const uint32_t groupY = cpuDevice ? kCpuGroupY : kGpuGroupY;
  const bool blocked = d.switches.probe || (d.pass != Pass::Fxaa && blocksPixels());
  const VkPipeline p = pipelines.get(d.pass, d.fmt, specKeyOf(d), error);
  if (!p && pipelines.compiling)
    return true;  // record nothing, but go on: every pipeline of the frame starts
  if (!p || rec.dispatchIndex >= kMaxDispatches) return false;
  if (depthMayChange && !pipelines.compiling) {
    // Its twin with depth the other way (both eyes', in the stereo pass), made before a frame needs it.
    PassDispatch twin = d;
    twin.switches.depthBits = d.switches.depthBits != 0 ? 0 : d.pass == Pass::Stereo ? 3 : 1;
    pipelines.prepare(twin.pass, twin.fmt, specKeyOf(twin));
  }
  const VkDeviceSize offset = uboStride * rec.dispatchIndex++;
  std::memcpy(static_cast<char*>(s.mapped) + offset, &d.uniforms, sizeof(d.uniforms));
  VkDescriptorSetAllocateInfo dsai{};
  dsai.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
  dsai.descriptorPool = s.descriptorPool.get();
  dsai.descriptorSetCount = 1;
  const VkDescriptorSetLayout dsl = setLayout;
  dsai.pSetLayouts = &dsl;
  VkDescriptorSet set = VK_NULL_HANDLE;
  if (vkAllocateDescriptorSets(device, &dsai, &set) != VK_SUCCESS)
    return fail(error, "descriptor pool"), false;
  // Unused bindings read and write 1x1 dummies: one layout for every pass.
  auto sampled = [&](VkSampler smp, const Binding& b) {
    return b.view ? VkDescriptorImageInfo{smp, b.view, b.layout}
                  : VkDescriptorImageInfo{smp, dummy16.view.get(), VK_IMAGE_LAYOUT_GENERAL};
  };
  const PassIo& io = d.io;
  const VkImageView outDummy = d.fmt == kOut8 ? dummy8.view.get() : dummy16.view.get();
  const bool history8 = d.switches.historyEncoding != 0;
  std::array<VkDescriptorImageInfo, kBindings> ii{{
      sampled(sampler.get(), io.src0),
      sampled(sampler.get(), io.src1),
      sampled(samplerNearest.get(), io.depth0),
      sampled(samplerNearest.get(), io.depth1),
      {VK_NULL_HANDLE,
       io.headLockedRecord          ? io.headLockedRecord
       : io.historyOut && !history8 ? io.historyOut
                                    : dummy16.view.get(),
       VK_IMAGE_LAYOUT_GENERAL},
      {VK_NULL_HANDLE, io.output ? io.output : outDummy, VK_IMAGE_LAYOUT_GENERAL},
      {},  // 6: the uniform buffer
      sampled(samplerNearest.get(), io.appInput),
      {VK_NULL_HANDLE, io.historyOut && history8 ? io.historyOut : dummy8.view.get(),
       VK_IMAGE_LAYOUT_GENERAL},
      {},  // 9: the noise histogram
      sampled(samplerNearest.get(), io.shownIn),
      {VK_NULL_HANDLE, io.shownOut ? io.shownOut : dummy8.view.get(), VK_IMAGE_LAYOUT_GENERAL},
  }};
  const VkDescriptorBufferInfo bi{s.ubo.get(), offset, sizeof(PassUniforms)};
  const VkDescriptorBufferInfo noiseInfo{s.ubo.get(), s.noiseOffset, detail::kStorageBufferBytes};
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
    else if (w[i].descriptorType == VK_DESCRIPTOR_TYPE_STORAGE_BUFFER)
      w[i].pBufferInfo = &noiseInfo;
    else
      w[i].pImageInfo = &ii[i];
  }
  vkUpdateDescriptorSets(device, static_cast<uint32_t>(w.size()), w.data(), 0, nullptr);
  if (p != rec.bound) vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, p);
  rec.bound = p;
  vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipelineLayout, 0, 1, &set, 0, nullptr);
  // blocked: each invocation handles 4x4 pixels (kBlockW x kBlockH); the probe's, one block of its own
  const uint32_t invocationPx = d.switches.probe ? static_cast<uint32_t>(d.uniforms.probeBlockPx)
                                : blocked        ? 4
                                                 : 1;
  const uint32_t gx = invocationPx * groupX;
  const uint32_t gy = invocationPx * groupY;
  vkCmdDispatch(cmd, (static_cast<uint32_t>(d.uniforms.src0Size.x) + gx - 1) / gx,
                (static_cast<uint32_t>(d.uniforms.src0Size.y) + gy - 1) / gy, 1);
  return true;
}

void Filter::Impl::transitionOut(VkCommandBuffer cmd, const StereoOutput& output, const FramePlan& plan,
                                 bool ok, std::vector<VkImageMemoryBarrier> post) {
  const uint32_t n = plan.viewCount;
  std::vector<VkImageMemoryBarrier> toCopy;
  for (uint32_t e = 0; e < n; ++e) {
    if (!plan.targets[e].scratch) continue;
    VkImageMemoryBarrier b{};
    b.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = plan.targets[e].scratch->image.get();
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
      if (!plan.targets[e].scratch) continue;
      const ImageRef& out = output.views[e];
      VkImageCopy region{};
      region.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
      region.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, out.arrayLayer, 1};
      region.dstOffset = {out.rect.offset.x, out.rect.offset.y, 0};
      region.extent = {out.rect.extent.width, out.rect.extent.height, 1};
      vkCmdCopyImage(cmd, plan.targets[e].scratch->image.get(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                     out.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
    }
  }
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                       VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 0, nullptr, 0, nullptr,
                       static_cast<uint32_t>(post.size()), post.data());
}

}  // namespace steadyxr::core
