// Move-only owners for the Vulkan handles the harness creates (destroyed with their device).
#pragma once

#include <vulkan/vulkan.h>

#include <utility>

namespace steadyxr::eval {

template <typename T, auto Destroy>
class DeviceHandle {
 public:
  DeviceHandle() = default;
  DeviceHandle(VkDevice device, T handle) : device_(device), handle_(handle) {}
  ~DeviceHandle() { reset(); }
  DeviceHandle(const DeviceHandle&) = delete;
  DeviceHandle& operator=(const DeviceHandle&) = delete;
  DeviceHandle(DeviceHandle&& other) noexcept
      : device_(other.device_), handle_(std::exchange(other.handle_, VK_NULL_HANDLE)) {}
  DeviceHandle& operator=(DeviceHandle&& other) noexcept {
    if (this != &other) {
      reset();
      device_ = other.device_;
      handle_ = std::exchange(other.handle_, VK_NULL_HANDLE);
    }
    return *this;
  }
  T get() const { return handle_; }
  void reset() {
    if (handle_ != VK_NULL_HANDLE) Destroy(device_, handle_, nullptr);
    handle_ = VK_NULL_HANDLE;
  }

 private:
  VkDevice device_ = VK_NULL_HANDLE;
  T handle_ = VK_NULL_HANDLE;
};

using UniqueImage = DeviceHandle<VkImage, &vkDestroyImage>;
using UniqueImageView = DeviceHandle<VkImageView, &vkDestroyImageView>;
using UniqueBuffer = DeviceHandle<VkBuffer, &vkDestroyBuffer>;
using UniqueMemory = DeviceHandle<VkDeviceMemory, &vkFreeMemory>;
using UniqueSampler = DeviceHandle<VkSampler, &vkDestroySampler>;
using UniqueRenderPass = DeviceHandle<VkRenderPass, &vkDestroyRenderPass>;
using UniqueFramebuffer = DeviceHandle<VkFramebuffer, &vkDestroyFramebuffer>;
using UniquePipeline = DeviceHandle<VkPipeline, &vkDestroyPipeline>;
using UniquePipelineLayout = DeviceHandle<VkPipelineLayout, &vkDestroyPipelineLayout>;
using UniqueSetLayout = DeviceHandle<VkDescriptorSetLayout, &vkDestroyDescriptorSetLayout>;
using UniqueDescriptorPool = DeviceHandle<VkDescriptorPool, &vkDestroyDescriptorPool>;
using UniqueShaderModule = DeviceHandle<VkShaderModule, &vkDestroyShaderModule>;
using UniqueCommandPool = DeviceHandle<VkCommandPool, &vkDestroyCommandPool>;
using UniqueFence = DeviceHandle<VkFence, &vkDestroyFence>;
using UniqueQueryPool = DeviceHandle<VkQueryPool, &vkDestroyQueryPool>;

}  // namespace steadyxr::eval
