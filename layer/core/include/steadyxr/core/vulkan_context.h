// The Vulkan objects the filter core runs on: either created by the core itself (tests,
// benchmarks, evaluation harness) or borrowed from an application (the OpenXR layer).
// Borrowed handles are never destroyed by the core.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace steadyxr::core {

class Filter;
namespace detail {
class PipelineStore;
}

struct OwnedContextOptions {
  bool enableValidation = false;  // VK_LAYER_KHRONOS_validation + a messenger that counts messages
  bool preferCpuDevice = true;    // pick VK_PHYSICAL_DEVICE_TYPE_CPU (lavapipe) when present
  std::string applicationName = "steadyxr";
};

struct BorrowedHandles {
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physicalDevice = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  uint32_t queueFamilyIndex = 0;
  uint32_t queueIndex = 0;
  uint32_t apiVersion = VK_API_VERSION_1_1;  // the version the app created its instance with
};

class VulkanContext {
 public:
  // Returns nullptr and fills *error on failure (no exceptions across the layer boundary).
  static std::unique_ptr<VulkanContext> createOwned(const OwnedContextOptions& options, std::string* error);
  static std::unique_ptr<VulkanContext> borrow(const BorrowedHandles& handles, std::string* error);

  ~VulkanContext();
  VulkanContext(const VulkanContext&) = delete;
  VulkanContext& operator=(const VulkanContext&) = delete;

  VkInstance instance() const;
  VkPhysicalDevice physicalDevice() const;
  VkDevice device() const;
  VkQueue queue() const;
  uint32_t queueFamilyIndex() const;
  bool owned() const;
  const VkPhysicalDeviceProperties& properties() const;
  uint32_t findMemoryType(uint32_t typeBits, VkMemoryPropertyFlags required) const;  // UINT32_MAX if none
  // A type with required | preferred if there is one, else one with required (UINT32_MAX if none).
  // On a discrete GPU the first type with no flags lives in system memory, behind PCIe.
  uint32_t findMemoryType(uint32_t typeBits, VkMemoryPropertyFlags required,
                          VkMemoryPropertyFlags preferred) const;
  bool isCpuDevice() const;  // lavapipe/llvmpipe: shaders run on the host's cores

  // Validation messages seen so far (owned contexts with enableValidation only).
  uint32_t validationMessageCount() const;
  std::vector<std::string> validationMessages() const;

  struct Impl;

 private:
  friend class Filter;
  // The compiled passes every Filter on this context shares, made on first use (null, with *error,
  // when its layouts cannot be made). Destroyed with the context, before an owned device.
  detail::PipelineStore* pipelineStore(std::string* error);

  explicit VulkanContext(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace steadyxr::core
