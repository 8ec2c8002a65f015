// steadyxr-shader-stats: what a GPU's shader compiler makes of the filter's pipelines, without running
// them: registers, spills, instructions and waves per SIMD, as the driver reports them through
// VK_KHR_pipeline_executable_properties. Mesa's RADV reports them with no AMD GPU present
// (RADV_FORCE_FAMILY=navi21 selects its compiler for that chip on null hardware), so this machine can
// see the register pressure that decides a pass's occupancy on a GPU (docs/cost.md, round 22).
// The pipelines are the filter's own: its SPIR-V, compiled through the core's compilePipeline with the
// specialisation `steadyxr-bench --pipelines` prints for a method. Figures, not a test.
#include <vulkan/vulkan.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "filter_pipelines.h"

using namespace steadyxr::core;
using namespace steadyxr::core::detail;

namespace {

void usage() {
  std::printf(
      "usage: steadyxr-shader-stats [--device NAME] [--gpu-shape] PASS:STORAGE:K0,...,K14 ...\n"
      "Compiles each pipeline (as `steadyxr-bench --pipelines` prints them) on the first device that\n"
      "reports pipeline executable statistics (or the first whose name contains NAME) and prints them.\n"
      "--gpu-shape: one pixel per invocation in 16x8 groups, as the filter dispatches on a GPU (the\n"
      "bench on lavapipe prints 4x4 blocks in 32x2 groups). Without a GPU:\n"
      "  RADV_FORCE_FAMILY=navi21 VK_ICD_FILENAMES=/usr/share/vulkan/icd.d/radeon_icd.x86_64.json \\\n"
      "    steadyxr-shader-stats --gpu-shape temporal:rgba8:...\n");
}

struct Pipeline {
  std::string text;
  Pass pass = Pass::Copy;
  OutFmt fmt = kOut8;
  SpecKey spec{};
};

bool parsePipeline(const std::string& text, bool gpuShape, Pipeline* p) {
  const size_t a = text.find(':'), b = text.find(':', a == std::string::npos ? a : a + 1);
  if (a == std::string::npos || b == std::string::npos) return false;
  if (!parsePass(text.substr(0, a), &p->pass) || !parseOutFmt(text.substr(a + 1, b - a - 1), &p->fmt))
    return false;
  std::stringstream values(text.substr(b + 1));
  size_t n = 0;
  for (std::string item; std::getline(values, item, ',');) {
    if (n == p->spec.size()) return false;
    char* end = nullptr;
    p->spec[n++] = static_cast<int32_t>(std::strtol(item.c_str(), &end, 10));
    if (end == item.c_str() || *end != '\0') return false;
  }
  if (n != p->spec.size()) return false;
  if (gpuShape) {
    p->spec[kSpecBlocked] = 0;
    p->spec[kSpecGroupX] = static_cast<int32_t>(kGpuGroupX);
    p->spec[kSpecGroupY] = static_cast<int32_t>(kGpuGroupY);
  }
  p->text = text;
  return true;
}

// The instance and device of this tool, destroyed in order.
struct Device {
  VkInstance instance = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  std::string name;
  Device() = default;
  Device(const Device&) = delete;
  Device& operator=(const Device&) = delete;
  ~Device() {
    if (device) vkDestroyDevice(device, nullptr);
    if (instance) vkDestroyInstance(instance, nullptr);
  }
};

bool hasExtension(VkPhysicalDevice pd, const char* name) {
  uint32_t n = 0;
  vkEnumerateDeviceExtensionProperties(pd, nullptr, &n, nullptr);
  std::vector<VkExtensionProperties> e(n);
  vkEnumerateDeviceExtensionProperties(pd, nullptr, &n, e.data());
  for (const auto& x : e)
    if (std::strcmp(x.extensionName, name) == 0) return true;
  return false;
}

bool createDevice(const std::string& wanted, Device* d, std::string* error) {
  VkApplicationInfo ai{};
  ai.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
  ai.apiVersion = VK_API_VERSION_1_1;
  VkInstanceCreateInfo ici{};
  ici.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
  ici.pApplicationInfo = &ai;
  if (vkCreateInstance(&ici, nullptr, &d->instance) != VK_SUCCESS)
    return *error = "no Vulkan instance", false;
  uint32_t n = 0;
  vkEnumeratePhysicalDevices(d->instance, &n, nullptr);
  std::vector<VkPhysicalDevice> devices(n);
  vkEnumeratePhysicalDevices(d->instance, &n, devices.data());
  const char* extension = VK_KHR_PIPELINE_EXECUTABLE_PROPERTIES_EXTENSION_NAME;
  for (VkPhysicalDevice pd : devices) {
    VkPhysicalDeviceProperties props;
    vkGetPhysicalDeviceProperties(pd, &props);
    if (!hasExtension(pd, extension) || std::string(props.deviceName).find(wanted) == std::string::npos)
      continue;
    VkPhysicalDevicePipelineExecutablePropertiesFeaturesKHR executables{};
    executables.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PIPELINE_EXECUTABLE_PROPERTIES_FEATURES_KHR;
    executables.pipelineExecutableInfo = VK_TRUE;
    const float priority = 1.0f;
    VkDeviceQueueCreateInfo qci{};
    qci.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
    qci.queueCount = 1;
    qci.pQueuePriorities = &priority;
    VkDeviceCreateInfo dci{};
    dci.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
    dci.pNext = &executables;
    dci.queueCreateInfoCount = 1;
    dci.pQueueCreateInfos = &qci;
    dci.enabledExtensionCount = 1;
    dci.ppEnabledExtensionNames = &extension;
    if (vkCreateDevice(pd, &dci, nullptr, &d->device) != VK_SUCCESS) continue;
    d->name = props.deviceName;
    return true;
  }
  *error = "no device reports pipeline executable statistics (VK_KHR_pipeline_executable_properties)";
  return false;
}

double statisticValue(const VkPipelineExecutableStatisticKHR& s) {
  switch (s.format) {
    case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_BOOL32_KHR:
      return s.value.b32 ? 1.0 : 0.0;
    case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_INT64_KHR:
      return static_cast<double>(s.value.i64);
    case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_UINT64_KHR:
      return static_cast<double>(s.value.u64);
    default:
      return s.value.f64;
  }
}

// One line per executable of the pipeline: every statistic the driver reports, by its name.
bool printStatistics(const Device& d, VkPipelineLayout layout, const Pipeline& p) {
  const CompiledPipeline c =
      compilePipeline(d.device, layout, p.pass, p.fmt, p.spec, VK_PIPELINE_CREATE_CAPTURE_STATISTICS_BIT_KHR);
  if (!c.pipeline) {
    std::fprintf(stderr, "%s: %s\n", p.text.c_str(), c.error.c_str());
    return false;
  }
  const Unique<VkPipeline> owner(d.device, c.pipeline);
  auto executables = reinterpret_cast<PFN_vkGetPipelineExecutablePropertiesKHR>(
      vkGetDeviceProcAddr(d.device, "vkGetPipelineExecutablePropertiesKHR"));
  auto statistics = reinterpret_cast<PFN_vkGetPipelineExecutableStatisticsKHR>(
      vkGetDeviceProcAddr(d.device, "vkGetPipelineExecutableStatisticsKHR"));
  if (!executables || !statistics) return false;
  VkPipelineInfoKHR info{};
  info.sType = VK_STRUCTURE_TYPE_PIPELINE_INFO_KHR;
  info.pipeline = c.pipeline;
  uint32_t n = 0;
  executables(d.device, &info, &n, nullptr);
  for (uint32_t e = 0; e < n; ++e) {
    VkPipelineExecutableInfoKHR ei{};
    ei.sType = VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_INFO_KHR;
    ei.pipeline = c.pipeline;
    ei.executableIndex = e;
    uint32_t count = 0;
    statistics(d.device, &ei, &count, nullptr);
    std::vector<VkPipelineExecutableStatisticKHR> stats(count);
    for (auto& s : stats) s.sType = VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_STATISTIC_KHR;
    statistics(d.device, &ei, &count, stats.data());
    std::printf("%s", p.text.c_str());
    for (const auto& s : stats)
      if (std::strstr(s.name, "hash") == nullptr && std::strstr(s.name, "Hash") == nullptr)
        std::printf(" | %s %g", s.name, statisticValue(s));
    std::printf("\n");
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  std::string wanted;
  bool gpuShape = false;
  std::vector<Pipeline> pipelines;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--device" && i + 1 < argc) {
      wanted = argv[++i];
    } else if (a == "--gpu-shape") {
      gpuShape = true;
    } else {
      Pipeline p;
      if (!parsePipeline(a, gpuShape, &p)) {
        std::fprintf(stderr, "not a pipeline: %s (PASS:STORAGE:15 integers; --gpu-shape before them)\n",
                     a.c_str());
        usage();
        return 2;
      }
      pipelines.push_back(p);
    }
  }
  if (pipelines.empty()) {
    usage();
    return 2;
  }
  Device d;
  std::string error;
  if (!createDevice(wanted, &d, &error)) {
    std::fprintf(stderr, "steadyxr-shader-stats: %s\n", error.c_str());
    return 1;
  }
  Unique<VkDescriptorSetLayout> setLayout;
  Unique<VkPipelineLayout> pipelineLayout;
  if (!createPassLayouts(d.device, &setLayout, &pipelineLayout)) {
    std::fprintf(stderr, "steadyxr-shader-stats: the passes' layouts\n");
    return 1;
  }
  std::printf("device: %s\n", d.name.c_str());
  bool ok = true;
  for (const Pipeline& p : pipelines) ok = printStatistics(d, pipelineLayout.get(), p) && ok;
  return ok ? 0 : 1;
}
