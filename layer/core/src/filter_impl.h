// Filter::Impl: the state the filter keeps between frames, and the named steps of submit.
#pragma once

#include <array>
#include <map>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "filter_passes.h"
#include "filter_pipelines.h"
#include "filter_resources.h"
#include "noise_estimate.h"
#include "steadyxr/core/filter.h"

namespace steadyxr::core {

struct Filter::Impl {
  using ViewKey = std::tuple<VkImage, VkFormat, uint32_t, VkImageAspectFlags>;

  VulkanContext& ctx;
  VkDevice device;
  Params params;
  Params pendingParams;
  bool paramsChanged = false;
  bool resetRequested = true;
  bool depthMayChange = false;  // Filter::setDepthMayChange
  bool timestamps = false;
  float timestampPeriodNs = 1.0f;
  VkDeviceSize uboStride = 512;

  Unique<VkSampler> sampler;         // linear: colour
  Unique<VkSampler> samplerNearest;  // depth (texelFetch only)
  VkDescriptorSetLayout setLayout;   // the context's pipeline store owns both layouts
  VkPipelineLayout pipelineLayout;
  detail::PipelineCache pipelines;
  std::array<detail::Slot, detail::kSlots> slots;
  std::array<detail::EyeState, 2> eyes;
  uint32_t historyIndex = 0;   // which history image is written this frame
  detail::OwnedImage dummy16;  // 1x1 RGBA16F: unused samplers and history writes
  detail::OwnedImage dummy8;   // 1x1 RGBA8: unused output writes
  std::map<ViewKey, Unique<VkImageView>> views;
  uint64_t frameCounter = 0;
  RenderSizeCounters sizeCounters;
  std::optional<PassTimings> timings;
  std::optional<GainProbeSums> gainProbe;  // the newest finished frame's, with samples
  // The render's noise variance per linear RGB channel from the finished frames that sampled it
  // (Params::steadyNoiseEstimate; noise_estimate.h), in the order they were submitted.
  detail::NoiseTracker noiseTracker;
  uint64_t noiseNextFrame = 0;          // frames before it are read, or from before the last reset
  detail::HeadLockedSwitch headLocked;  // round 42: whether the app draws head-locked content

  Impl(VulkanContext& c, detail::PipelineStore& store, const FilterOptions& options)
      : ctx(c),
        device(c.device()),
        setLayout(store.setLayout()),
        pipelineLayout(store.layout()),
        pipelines(store, options) {}
  ~Impl() { waitAll(); }

  // Resources (filter_resources.cpp).
  bool init(std::string* error);
  bool createImage(detail::OwnedImage& img, VkExtent2D extent, VkFormat format, VkImageUsageFlags usage,
                   std::string* error);
  bool createMappedBuffer(VkDeviceSize size, VkBufferUsageFlags usage, VkMemoryPropertyFlags preferred,
                          detail::MappedBuffer& out, void** mapped, std::string* error);
  VkImageView view(VkImage image, VkFormat format, uint32_t layer, VkImageAspectFlags aspect,
                   std::string* error);
  void collect(detail::Slot& s);  // waits for the slot's frame, reads its timestamps and noise histogram
  void collectFinished();         // collect() of every slot whose frame has finished, without waiting
  void waitAll();
  static const uint32_t* noiseBins(const detail::Slot& s);  // the slot's records as the host reads them
  static const uint32_t* gainRecord(
      const detail::Slot& s);                 // the gain record among them (and round 42's count)
  void readGainProbe(const detail::Slot& s);  // the slot's gain record into gainProbe (collect)

  // submit and its steps, in order (filter_submit.cpp).
  bool submit(const StereoFrame& frame, const StereoOutput& output, std::string* error, VkSemaphore signal);
  void applyPendingParams();
  // Round 42: the head-locked switch's steps for this frame's probes, and the eyes' record images.
  bool planHeadLocked(const StereoFrame& frame, detail::FramePlan& plan, std::string* error);
  bool checkInputs(const StereoFrame& frame, const StereoOutput& output, detail::FramePlan& plan,
                   std::string* error) const;
  bool prepareEyes(const StereoFrame& frame, detail::FramePlan& plan, std::string* error);
  bool bindTargets(const StereoFrame& frame, const StereoOutput& output, detail::FramePlan& plan,
                   std::string* error);
  void zeroRecords(detail::Slot& s);     // the noise and gain records, on the GPU
  void copyRecordsOut(detail::Slot& s);  // into s.records for collect()
  bool recordPasses(detail::Slot& s, const StereoFrame& frame, const StereoOutput& output,
                    const detail::FramePlan& plan, std::string* error);
  bool submitRecording(detail::Slot& s, VkSemaphore signal, std::string* error);
  void advanceEyes(const StereoFrame& frame, const detail::FramePlan& plan);

  // Command recording (filter_record.cpp).
  detail::Slot& beginRecording();
  // Layout transitions of every image the frame touches into the layouts the passes use; returns
  // the barriers that turn the app's images back into their final layouts.
  std::vector<VkImageMemoryBarrier> transitionIn(VkCommandBuffer cmd, const StereoFrame& frame,
                                                 const StereoOutput& output, const detail::FramePlan& plan);
  // Scratch outputs copied to the app's images, then every image back to its final layout.
  void transitionOut(VkCommandBuffer cmd, const StereoOutput& output, const detail::FramePlan& plan, bool ok,
                     std::vector<VkImageMemoryBarrier> post);
  void timestamp(const detail::Slot& s, uint32_t query);
  // The dispatches of one frame so far: each takes the next uniform buffer range.
  struct Recording {
    detail::Slot& slot;
    uint32_t dispatchIndex = 0;
    VkPipeline bound = VK_NULL_HANDLE;
  };
  // One dispatch: its pipeline, uniforms and descriptor set. True when recorded, or skipped only
  // because its pipeline is still compiling.
  bool record(Recording& rec, const detail::PassDispatch& d, std::string* error);
  // The pipeline's key of a dispatch on this device.
  detail::SpecKey specKeyOf(const detail::PassDispatch& d) const;
  // Whether the passes (all but fxaa) run 4x4 pixels an invocation: Params::invocationBlock, by the device.
  bool blocksPixels() const;
  bool stagesHeldOutput(const detail::FramePlan& plan, uint32_t e, bool directStorage) const;
  // Steady's gain probes of both eyes (Params::steadyGainCompensation), before its temporal passes.
  bool recordProbes(Recording& rec, const detail::PassContext& c, bool probesGain, std::string* error);
};

}  // namespace steadyxr::core
