// The compute pipelines of the filter's passes, one per specialisation, compiled on demand.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <future>
#include <map>
#include <mutex>
#include <string>
#include <tuple>

#include <vulkan/vulkan.h>

#include "steadyxr/core/filter.h"
#include "steadyxr/core/vk_handle.h"

namespace steadyxr::core::detail {

enum class Pass : uint32_t { Copy, Temporal, Stereo, Fxaa, Count };
// The storage format the pass writes its output in (each shader comes in both variants).
enum OutFmt : uint32_t { kOut8 = 0, kOut16 = 1 };

// The specialisation constants 0-14 of common.glsl, in constant_id order (passSpecKey builds it).
using SpecKey = std::array<int32_t, 15>;

struct CompiledPipeline {
  VkPipeline pipeline = VK_NULL_HANDLE;
  std::string error;
};

// Workgroup size (spec constants 11 and 12 in common.glsl). On llvmpipe a 32x2 group of 4x4
// blocks measured best (steadyxr-bench, 1024x1024: default 42-44 ms against 47-49 with 16x8);
// GPUs keep the 16x8 measured on the H100.
constexpr uint32_t kCpuGroupX = 32, kCpuGroupY = 2;
constexpr uint32_t kGpuGroupX = 16, kGpuGroupY = 8;
// Where SpecKey holds kBlocked and the workgroup size (constant_id 10, 11, 12).
constexpr size_t kSpecBlocked = 10, kSpecGroupX = 11, kSpecGroupY = 12;

// The descriptor set layout every pass shares (common.glsl's bindings) and the pipeline layout of it.
bool createPassLayouts(VkDevice device, Unique<VkDescriptorSetLayout>* setLayout,
                       Unique<VkPipelineLayout>* pipelineLayout);

// Creates one compute pipeline. Touches nothing but its arguments, so it may run on a worker
// thread: vkCreateShaderModule and vkCreateComputePipelines need no external synchronisation.
// flags: VK_PIPELINE_CREATE_CAPTURE_STATISTICS_BIT_KHR for steadyxr-shader-stats, else 0.
CompiledPipeline compilePipeline(VkDevice device, VkPipelineLayout layout, Pass pass, OutFmt fmt,
                                 SpecKey spec, VkPipelineCreateFlags flags = 0);
// The names PipelineDescription uses, and back (false: not a pass or format of the filter).
const char* passName(Pass pass);
const char* outFmtName(OutFmt fmt);
bool parsePass(const std::string& name, Pass* pass);
bool parseOutFmt(const std::string& name, OutFmt* fmt);

// One pipeline of the store: made, being compiled on a worker thread, or failed.
struct PipelineSlot {
  Unique<VkPipeline> pipeline;
  std::future<CompiledPipeline> pending;
  std::string error;
  VkDevice device = VK_NULL_HANDLE;

  PipelineSlot() = default;
  PipelineSlot(const PipelineSlot&) = delete;
  PipelineSlot& operator=(const PipelineSlot&) = delete;
  ~PipelineSlot();
};

using PipelineKey = std::tuple<Pass, OutFmt, SpecKey>;

// The compiled passes every Filter on one VulkanContext shares, with the layouts they are made for
// (VulkanContext owns it). A pipeline belongs to the device, not to one filter: a second filter
// with the same passes (a test's, the evaluation's methods, a method switched back) compiles
// nothing again, where each used to pay lavapipe about 0.4 s a pipeline. Thread-safe.
class PipelineStore {
 public:
  explicit PipelineStore(VkDevice device) : device_(device) {}
  bool init(std::string* error);  // the layouts
  VkDescriptorSetLayout setLayout() const { return setLayout_.get(); }
  VkPipelineLayout layout() const { return layout_.get(); }

  // The key's pipeline once it is made. Not made yet: compiled at once, or (background) on a worker
  // thread, returning null with *compiling set until it is ready. A failed compile is not retried.
  VkPipeline get(const PipelineKey& key, bool background, bool* compiling, std::string* error);

 private:
  VkDevice device_;
  Unique<VkDescriptorSetLayout> setLayout_;
  Unique<VkPipelineLayout> layout_;
  std::mutex mutex_;
  std::map<PipelineKey, PipelineSlot> slots_;  // declared last: destroyed (and joined) before the layouts
};

// One filter's view of the store: how it compiles (compileInBackground) and which pipelines it used.
// While one compiles, get() returns null and sets compiling, and the caller passes the frame through.
class PipelineCache {
 public:
  PipelineCache(PipelineStore& store, const FilterOptions& options)
      : store_(store), background_(options.compileInBackground), holdBack_(options.holdBackForTests) {}

  VkPipeline get(Pass pass, OutFmt fmt, const SpecKey& spec, std::string* error);
  // The same, for a pipeline a later frame may need (round 42: the head-locked switch's probe): null while it
  // compiles, without marking this frame's passes as compiling; a failed compile stays null.
  VkPipeline ready(Pass pass, OutFmt fmt, const SpecKey& spec);
  // Starts a pipeline's compile on a worker thread where this filter compiles in the background (and does
  // nothing where it compiles in line): for one that no frame needs yet (Filter::setDepthMayChange).
  void prepare(Pass pass, OutFmt fmt, const SpecKey& spec);
  std::vector<PipelineDescription> made() const;  // the pipelines this filter used so far
  bool compiling = false;                         // a get() of this frame found its pipeline still compiling

 private:
  VkPipeline getOrHoldBack(const PipelineKey& key, bool* stillCompiling, std::string* error);

  PipelineStore& store_;
  bool background_;
  std::function<bool(const PipelineDescription&)> holdBack_;  // FilterOptions::holdBackForTests
  std::map<PipelineKey, VkPipeline> used_;                    // the store's, which outlives the filter
};

}  // namespace steadyxr::core::detail
