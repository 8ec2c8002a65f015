// The compute pipelines of the filter's passes, one per specialisation, compiled on demand.
#include "filter_pipelines.h"

#include <chrono>
#include <system_error>

#include "filter_error.h"
#include "filter_resources.h"

#include "steadyxr/shaders/copy_rgba16f_spv.h"
#include "steadyxr/shaders/copy_rgba8_spv.h"
#include "steadyxr/shaders/fxaa_rgba16f_spv.h"
#include "steadyxr/shaders/fxaa_rgba8_spv.h"
#include "steadyxr/shaders/stereo_rgba16f_spv.h"
#include "steadyxr/shaders/stereo_rgba8_spv.h"
#include "steadyxr/shaders/temporal_rgba16f_spv.h"
#include "steadyxr/shaders/temporal_rgba8_spv.h"

namespace steadyxr::core::detail {

bool createPassLayouts(VkDevice device, Unique<VkDescriptorSetLayout>* setLayout,
                       Unique<VkPipelineLayout>* pipelineLayout) {
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
  if (vkCreateDescriptorSetLayout(device, &dlci, nullptr, &dsl) != VK_SUCCESS) return false;
  *setLayout = Unique<VkDescriptorSetLayout>(device, dsl);
  VkPipelineLayoutCreateInfo plci{};
  plci.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
  plci.setLayoutCount = 1;
  plci.pSetLayouts = &dsl;
  VkPipelineLayout pl = VK_NULL_HANDLE;
  if (vkCreatePipelineLayout(device, &plci, nullptr, &pl) != VK_SUCCESS) return false;
  *pipelineLayout = Unique<VkPipelineLayout>(device, pl);
  return true;
}

namespace {
constexpr std::array<const char*, static_cast<size_t>(Pass::Count)> kPassNames{"copy", "temporal", "stereo",
                                                                               "fxaa"};
constexpr std::array<const char*, 2> kOutFmtNames{"rgba8", "rgba16f"};  // kOut8, kOut16
}  // namespace

const char* passName(Pass pass) {
  return pass < Pass::Count ? kPassNames[static_cast<size_t>(pass)] : "?";
}
const char* outFmtName(OutFmt fmt) {
  return fmt == kOut8 ? kOutFmtNames[0] : kOutFmtNames[1];
}
bool parsePass(const std::string& name, Pass* pass) {
  for (size_t i = 0; i < kPassNames.size(); ++i)
    if (name == kPassNames[i]) return *pass = static_cast<Pass>(i), true;
  return false;
}
bool parseOutFmt(const std::string& name, OutFmt* fmt) {
  if (name != kOutFmtNames[0] && name != kOutFmtNames[1]) return false;
  *fmt = name == kOutFmtNames[0] ? kOut8 : kOut16;
  return true;
}

CompiledPipeline compilePipeline(VkDevice device, VkPipelineLayout layout, Pass pass, OutFmt fmt,
                                 SpecKey spec, VkPipelineCreateFlags flags) {
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
  cpci.flags = flags;
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

PipelineSlot::~PipelineSlot() {
  if (!pending.valid()) return;
  const CompiledPipeline c = pending.get();  // joins the worker; its pipeline was never used
  if (c.pipeline) vkDestroyPipeline(device, c.pipeline, nullptr);
}

bool PipelineStore::init(std::string* error) {
  if (createPassLayouts(device_, &setLayout_, &layout_)) return true;
  fail(error, "the passes' descriptor set or pipeline layout");
  return false;
}

VkPipeline PipelineStore::get(const PipelineKey& key, bool background, bool* compiling, std::string* error) {
  std::lock_guard lock(mutex_);
  PipelineSlot& slot = slots_[key];
  if (slot.pipeline) return slot.pipeline.get();
  if (!slot.error.empty()) {  // failed before: not retried every frame
    fail(error, slot.error);
    return VK_NULL_HANDLE;
  }
  slot.device = device_;
  const auto& [pass, fmt, spec] = key;
  if (!slot.pending.valid()) {
    if (background) {
      try {
        slot.pending =
            std::async(std::launch::async, compilePipeline, device_, layout_.get(), pass, fmt, spec, 0);
      } catch (const std::system_error&) {  // no thread to be had: compile here instead
      }
    }
    if (!slot.pending.valid()) {
      std::promise<CompiledPipeline> now;
      now.set_value(compilePipeline(device_, layout_.get(), pass, fmt, spec, 0));
      slot.pending = now.get_future();
    }
  }
  if (slot.pending.wait_for(std::chrono::seconds(0)) != std::future_status::ready) {
    *compiling = true;
    fail(error, "the filter's pipelines are still compiling");
    return VK_NULL_HANDLE;
  }
  CompiledPipeline c = slot.pending.get();
  if (!c.pipeline) {
    slot.error = c.error;
    fail(error, slot.error);
    return VK_NULL_HANDLE;
  }
  slot.pipeline = Unique<VkPipeline>(device_, c.pipeline);
  return c.pipeline;
}

namespace {
PipelineDescription describe(const PipelineKey& key) {
  const auto& [pass, fmt, spec] = key;
  return {passName(pass), outFmtName(fmt), std::vector<int32_t>(spec.begin(), spec.end())};
}
}  // namespace

VkPipeline PipelineCache::getOrHoldBack(const PipelineKey& key, bool* stillCompiling, std::string* error) {
  if (const auto it = used_.find(key); it != used_.end()) return it->second;  // every frame: no lock
  const VkPipeline p = store_.get(key, background_, stillCompiling, error);
  if (p && holdBack_ && holdBack_(describe(key))) {
    *stillCompiling = true;
    fail(error, "the filter's pipelines are still compiling");
    return VK_NULL_HANDLE;
  }
  if (p) used_.emplace(key, p);
  return p;
}

VkPipeline PipelineCache::get(Pass pass, OutFmt fmt, const SpecKey& spec, std::string* error) {
  return getOrHoldBack({pass, fmt, spec}, &compiling, error);
}

VkPipeline PipelineCache::ready(Pass pass, OutFmt fmt, const SpecKey& spec) {
  bool stillCompiling = false;
  std::string error;
  return getOrHoldBack({pass, fmt, spec}, &stillCompiling, &error);
}

void PipelineCache::prepare(Pass pass, OutFmt fmt, const SpecKey& spec) {
  if (background_) ready(pass, fmt, spec);
}

std::vector<PipelineDescription> PipelineCache::made() const {
  std::vector<PipelineDescription> out;
  for (const auto& [key, pipeline] : used_) out.push_back(describe(key));
  return out;
}

}  // namespace steadyxr::core::detail
