// The GPU objects the filter owns: internal images, the per-frame slots, each eye's history.
#pragma once

#include <array>
#include <cstdint>

#include <vulkan/vulkan.h>

#include "steadyxr/core/frame.h"
#include "steadyxr/core/vk_handle.h"

namespace steadyxr::core::detail {

// Frames in flight: a slot's resources are reused kSlots frames later, after its fence.
constexpr uint32_t kSlots = 3;
// Dispatches per frame at most: two eyes times (first stage + stereo), with room to spare.
constexpr uint32_t kMaxDispatches = 8;
// Timestamps per frame: start, after the first stage, after stereo, end, after the probe (PassTimings).
constexpr uint32_t kQueries = 5;

// The one descriptor set layout of every pass (common.glsl): 0-3 samplers (src0, src1, depth0,
// depth1), 4-5 storage images (history out, output), 6 the uniforms, 7 a sampler (the app's
// input of this eye, whose alpha every output carries), 8 the 8-bit history out, 9 the frame's
// noise histogram (noise_estimate.h), 10-11 the codes the 8-bit output showed last frame (a sampler)
// and shows this frame (a storage image; Params::steadyOutputHold).
constexpr uint32_t kBindings = 12;
constexpr VkDescriptorType descriptorType(uint32_t binding) {
  return binding < 4 || binding == 7 || binding == 10   ? VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER
         : binding < 6 || binding == 8 || binding == 11 ? VK_DESCRIPTOR_TYPE_STORAGE_IMAGE
         : binding == 9                                 ? VK_DESCRIPTOR_TYPE_STORAGE_BUFFER
                                                        : VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
}

struct OwnedImage {
  Unique<VkImage> image;
  Unique<VkDeviceMemory> memory;
  Unique<VkImageView> view;
  VkExtent2D extent{};
  VkFormat format = VK_FORMAT_UNDEFINED;
  VkDeviceSize bytes = 0;    // the device memory it holds
  bool initialised = false;  // transitioned from UNDEFINED to GENERAL
  bool clearOnInit = false;  // cleared to 0 then: texels outside the rect stay finite for bilinear taps
};

// A buffer and its memory (the memory freed after the buffer is destroyed).
struct MappedBuffer {
  Unique<VkDeviceMemory> memory;
  Unique<VkBuffer> buffer;
  VkBuffer get() const { return buffer.get(); }
};

// What one frame in flight records into and reads its uniforms from.
struct Slot {
  Unique<VkCommandPool> pool;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  Unique<VkFence> fence;
  Unique<VkDescriptorPool> descriptorPool;
  MappedBuffer ubo;
  void* mapped = nullptr;
  VkDeviceSize noiseOffset = 0;  // the noise histogram's place in ubo (after the uniforms)
  MappedBuffer records;          // the noise and gain records copied out of ubo for the host
  void* recordsMapped = nullptr;
  Unique<VkQueryPool> queries;
  bool pending = false;
  bool timed = false;
  bool noiseSampled = false;         // a pass of the frame filled the noise histogram
  bool gainProbed = false;           // the frame's gain probe filled its record
  bool headLockedTestified = false;  // its probe testified for the head-locked switch (filter_head_locked.h)
  uint64_t frameIndex = 0;
};

struct EyeState {
  std::array<OwnedImage, 2> history;  // ping-pong, RGBA16F, linear light
  std::array<OwnedImage, 2> scratch;  // intermediates for outputs without storage: [kOut8], [kOut16]
  std::array<OwnedImage, 2> shown;    // ping-pong with history, RGBA8: the 8-bit output's codes (hold)
  // Round 42: RGBA16F, one texel a probe sample: the reference's block luma (in r and a), 1 + the sample's
  // head-locked testimonies, its world testimonies (Params::steadyHeadLockedSwitch, shaders/probe.glsl).
  OwnedImage headLockedRecord;
  bool valid = false;
  bool shownWritten = false;  // this frame's temporal pass writes shown[] (the stereo pass does not)
  bool shownValid = false;    // it did last frame
  bool shownBgra = false;     // they were in BGRA order (the output's staging for a BGRA image)
  Pose prevPose;
  Fov prevFov;
  // The internal images' extent. Any rect that fits keeps the history (an app's dynamic resolution): each
  // history image holds the rect it was last written at, from its top-left corner.
  VkExtent2D capacity{};
  std::array<VkExtent2D, 2> written{};  // that rect's size per history image, once its frame was submitted
  VkExtent2D lastSize{};  // the rect's size in the last frame filtered (kept across reallocation)
};

}  // namespace steadyxr::core::detail
