// The compute pipelines of the filter's passes, one per specialisation, compiled on demand.
#pragma once

#include <array>
#include <cstdint>
#include <future>
#include <map>
#include <string>
#include <tuple>

#include <vulkan/vulkan.h>

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

// Creates one compute pipeline. Touches nothing but its arguments, so it may run on a worker
// thread: vkCreateShaderModule and vkCreateComputePipelines need no external synchronisation.
CompiledPipeline compilePipeline(VkDevice device, VkPipelineLayout layout, Pass pass, OutFmt fmt,
                                 SpecKey spec);

// One pipeline of the cache: made, being compiled on a worker thread, or failed.
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

// Pipelines by (pass, output format, specialisation). A pipeline not yet made is compiled on a
// worker thread (compileInBackground) or at once; while one compiles, get() returns null and sets
// compiling, and the caller passes the frame through.
class PipelineCache {
 public:
  PipelineCache(VkDevice device, bool compileInBackground)
      : device_(device), background_(compileInBackground) {}
  void setLayout(VkPipelineLayout layout) { layout_ = layout; }

  VkPipeline get(Pass pass, OutFmt fmt, const SpecKey& spec, std::string* error);
  bool compiling = false;  // a get() of this frame found its pipeline still compiling

 private:
  VkDevice device_;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  bool background_;
  std::map<std::tuple<Pass, OutFmt, SpecKey>, PipelineSlot> slots_;
};

}  // namespace steadyxr::core::detail
