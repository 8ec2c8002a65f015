// The one move-only owner for Vulkan device-child handles, used by the core, the layer, the
// benchmark and the evaluation harness. Borrowed (app or runtime) handles are never wrapped.
#pragma once

#include <vulkan/vulkan.h>

#include <utility>

namespace steadyxr::core {

template <typename T>
using DestroyFn = void (*)(VkDevice, T, const VkAllocationCallbacks*);

// How each handle type is released; Unique<T> uses it unless given another function.
template <typename T>
inline constexpr DestroyFn<T> kDefaultDestroy = nullptr;
template <>
inline constexpr DestroyFn<VkImage> kDefaultDestroy<VkImage> = vkDestroyImage;
template <>
inline constexpr DestroyFn<VkImageView> kDefaultDestroy<VkImageView> = vkDestroyImageView;
template <>
inline constexpr DestroyFn<VkDeviceMemory> kDefaultDestroy<VkDeviceMemory> = vkFreeMemory;
template <>
inline constexpr DestroyFn<VkBuffer> kDefaultDestroy<VkBuffer> = vkDestroyBuffer;
template <>
inline constexpr DestroyFn<VkCommandPool> kDefaultDestroy<VkCommandPool> = vkDestroyCommandPool;
template <>
inline constexpr DestroyFn<VkFence> kDefaultDestroy<VkFence> = vkDestroyFence;
template <>
inline constexpr DestroyFn<VkSemaphore> kDefaultDestroy<VkSemaphore> = vkDestroySemaphore;
template <>
inline constexpr DestroyFn<VkDescriptorPool> kDefaultDestroy<VkDescriptorPool> = vkDestroyDescriptorPool;
template <>
inline constexpr DestroyFn<VkDescriptorSetLayout> kDefaultDestroy<VkDescriptorSetLayout> =
    vkDestroyDescriptorSetLayout;
template <>
inline constexpr DestroyFn<VkPipelineLayout> kDefaultDestroy<VkPipelineLayout> = vkDestroyPipelineLayout;
template <>
inline constexpr DestroyFn<VkPipeline> kDefaultDestroy<VkPipeline> = vkDestroyPipeline;
template <>
inline constexpr DestroyFn<VkShaderModule> kDefaultDestroy<VkShaderModule> = vkDestroyShaderModule;
template <>
inline constexpr DestroyFn<VkSampler> kDefaultDestroy<VkSampler> = vkDestroySampler;
template <>
inline constexpr DestroyFn<VkQueryPool> kDefaultDestroy<VkQueryPool> = vkDestroyQueryPool;
template <>
inline constexpr DestroyFn<VkRenderPass> kDefaultDestroy<VkRenderPass> = vkDestroyRenderPass;
template <>
inline constexpr DestroyFn<VkFramebuffer> kDefaultDestroy<VkFramebuffer> = vkDestroyFramebuffer;

// Owns one device-child handle and releases it with its destroy function.
template <typename T>
class Unique {
 public:
  Unique() = default;
  Unique(VkDevice device, T handle, DestroyFn<T> destroy = kDefaultDestroy<T>)
      : device_(device), handle_(handle), destroy_(destroy) {}
  ~Unique() { reset(); }
  Unique(const Unique&) = delete;
  Unique& operator=(const Unique&) = delete;
  Unique(Unique&& o) noexcept { *this = std::move(o); }
  Unique& operator=(Unique&& o) noexcept {
    if (this != &o) {
      reset();
      device_ = o.device_;
      handle_ = std::exchange(o.handle_, T(VK_NULL_HANDLE));
      destroy_ = o.destroy_;
    }
    return *this;
  }
  T get() const { return handle_; }
  explicit operator bool() const { return handle_ != T(VK_NULL_HANDLE); }
  void reset() {
    if (handle_ != T(VK_NULL_HANDLE) && destroy_) destroy_(device_, handle_, nullptr);
    handle_ = T(VK_NULL_HANDLE);
  }

 private:
  VkDevice device_ = VK_NULL_HANDLE;
  T handle_ = T(VK_NULL_HANDLE);
  DestroyFn<T> destroy_ = nullptr;
};

}  // namespace steadyxr::core
