// The filter core: GPU compute passes that turn a stereo frame into filtered display images.
// Independent of OpenXR; the layer and the evaluation harness both drive this class.
#pragma once

#include "steadyxr/core/frame.h"
#include "steadyxr/core/params.h"
#include "steadyxr/core/vulkan_context.h"

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace steadyxr::core {

// The format of the history images for this input format: R8G8B8A8_UNORM (sqrt-encoded, decoded
// by the temporal pass: common.glsl storeHistory) for an 8-bit history of an 8-bit input without
// the stereo pass (which reads the history as it is) and with the bilinear history filter, else
// RGBA16F.
VkFormat historyFormat(const Params& params, VkFormat inputFormat);

// One compute pipeline the filter made (diagnostics): its pass (copy, temporal, stereo, fxaa), the storage
// format it writes (rgba8, rgba16f) and its specialisation constants in constant_id order (common.glsl).
struct PipelineDescription {
  std::string pass;
  std::string storage;
  std::vector<int32_t> specialisation;
};

// Input images need VK_IMAGE_USAGE_SAMPLED_BIT. Output images need VK_IMAGE_USAGE_STORAGE_BIT
// (with a storage-capable format, or mutableFormat so the core can make a UNORM view of an SRGB
// image) or else VK_IMAGE_USAGE_TRANSFER_DST_BIT (the core then writes an intermediate image and
// copies). Depth images need VK_IMAGE_USAGE_SAMPLED_BIT.
//
// submit() records the frame into the next of a small ring of command buffers, each with its own
// fence, and submits it to the context's queue. Before reusing a slot it waits for that slot's
// fence only (work from several frames ago), never for the whole queue. Queue submission order
// makes the app's earlier rendering visible (the first barrier has srcStage ALL_COMMANDS).
// The caller must hold whatever lock guards the queue.
struct FilterOptions {
  // Compile pipelines on worker threads. Until the pipelines a frame needs are ready, submit()
  // returns false with compiling() true and the caller passes the frame through, instead of the
  // frame stalling for the compile (measured for a first frame: 147 ms on an H100, 140-170 ms on
  // lavapipe). A host app's frame loop (the layer) wants this; tests and benchmarks want every
  // frame filtered.
  bool compileInBackground = false;
  // Tests only: a pipeline for which this returns true counts as still compiling (its compile runs
  // as usual), so that a test can order the compiles that worker threads finish in any order.
  std::function<bool(const PipelineDescription&)> holdBackForTests;
};

// Round 42: the head-locked switch's evidence (Filter::headLockedEvidence). Frames are counted by submit,
// from 0.
struct HeadLockedEvidence {
  uint64_t frame = 0;  // the newest epoch read back: the frame that ended it
  uint32_t steadySamples =
      0;                // then: samples (both eyes) that testified head-locked in 2 epochs, never world
  uint32_t epochs = 0;  // epochs read back
  std::optional<uint64_t> decidedFrame;  // the frame whose evidence decided, if any
};

class Filter {
 public:
  static std::unique_ptr<Filter> create(VulkanContext& context, const Params& params, std::string* error,
                                        const FilterOptions& options = {});
  ~Filter();
  Filter(const Filter&) = delete;
  Filter& operator=(const Filter&) = delete;

  // Filters `frame` into `output`. Returns false (and fills *error) when the frame cannot be
  // filtered; the caller then passes the frame through. Never throws.
  // signalSemaphore (optional) is signalled when the work finishes.
  bool submit(const StereoFrame& frame, const StereoOutput& output, std::string* error,
              VkSemaphore signalSemaphore = VK_NULL_HANDLE);
  // The last submit() returned false only because pipelines are still compiling in the
  // background (FilterOptions::compileInBackground); a later frame will be filtered.
  bool compiling() const;

  void setParams(const Params& params);  // takes effect on the next submit; method change resets history
  const Params& params() const;          // in force (round 42: with the profile hud's settings once switched)
  void reset();                          // history is reinitialised on the next submit
  // The app may start or stop giving depth half-way (it has depth images). With compileInBackground,
  // every filtered frame then also asks for its pipelines' twins with depth the other way, so that a
  // frame that gives depth where the last did not (or the reverse) finds them made and is not passed
  // through while they compile (round 45). Off by default: no compile for an input that cannot come.
  void setDepthMayChange(bool mayChange);

  // Blocks until all submitted work is done (tests, shutdown).
  void waitIdle();

  // GPU timings of the newest completed frame (timestamp queries), if the queue supports them.
  std::optional<PassTimings> lastTimings() const;
  // The render's noise variance per linear RGB channel that steady estimated from the newest
  // finished frame since the last reset (Params::steadyNoiseEstimate), if any.
  std::optional<float> estimatedNoiseVariance() const;
  // The gain probe's sums of the newest finished frame that had samples (a history), if any.
  std::optional<GainProbeSums> lastGainProbe() const;
  // Round 42 (Params::steadyHeadLockedSwitch): what the probe has found of head-locked content since the
  // start (reset() forgets it), once an epoch's evidence was read back. From the frame after the host read
  // the decision, params() holds the profile hud's settings.
  std::optional<HeadLockedEvidence> headLockedEvidence() const;
  // The filtered frames' changes of render size, and what became of the history across them.
  RenderSizeCounters renderSizeCounters() const;
  // The device memory of the filter's own images (each eye's history and their companions), in bytes.
  uint64_t imageMemoryBytes() const;

  // The pipelines made so far, in no particular order (steadyxr-bench --pipelines prints them for
  // steadyxr-shader-stats).
  std::vector<PipelineDescription> pipelines() const;

  // Forget cached views/descriptors of an image that the caller is about to destroy.
  void forgetImage(VkImage image);

  struct Impl;

 private:
  explicit Filter(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace steadyxr::core
