// Small RAII owners for the Vulkan objects the layer itself creates (the app's and the
// runtime's handles are never destroyed by the layer).
#pragma once

#include <vulkan/vulkan.h>

#include <utility>

namespace steadyxr::layer {

template <typename T, void (*Destroy)(VkDevice, T, const VkAllocationCallbacks*)>
class DeviceHandle {
 public:
  DeviceHandle() = default;
  DeviceHandle(VkDevice device, T handle) : device_(device), handle_(handle) {}
  ~DeviceHandle() { reset(); }
  DeviceHandle(const DeviceHandle&) = delete;
  DeviceHandle& operator=(const DeviceHandle&) = delete;
  DeviceHandle(DeviceHandle&& o) noexcept
      : device_(o.device_), handle_(std::exchange(o.handle_, static_cast<T>(VK_NULL_HANDLE))) {}
  DeviceHandle& operator=(DeviceHandle&& o) noexcept {
    if (this != &o) {
      reset();
      device_ = o.device_;
      handle_ = std::exchange(o.handle_, static_cast<T>(VK_NULL_HANDLE));
    }
    return *this;
  }
  void reset() {
    if (handle_ != VK_NULL_HANDLE) Destroy(device_, handle_, nullptr);
    handle_ = VK_NULL_HANDLE;
  }
  T get() const { return handle_; }
  explicit operator bool() const { return handle_ != VK_NULL_HANDLE; }

 private:
  VkDevice device_ = VK_NULL_HANDLE;
  T handle_ = VK_NULL_HANDLE;
};

inline void destroyCommandPool(VkDevice d, VkCommandPool h, const VkAllocationCallbacks* a) {
  vkDestroyCommandPool(d, h, a);
}
inline void destroyFence(VkDevice d, VkFence h, const VkAllocationCallbacks* a) {
  vkDestroyFence(d, h, a);
}
inline void destroyBuffer(VkDevice d, VkBuffer h, const VkAllocationCallbacks* a) {
  vkDestroyBuffer(d, h, a);
}
inline void freeMemory(VkDevice d, VkDeviceMemory h, const VkAllocationCallbacks* a) {
  vkFreeMemory(d, h, a);
}

using CommandPool = DeviceHandle<VkCommandPool, destroyCommandPool>;
using Fence = DeviceHandle<VkFence, destroyFence>;
using Buffer = DeviceHandle<VkBuffer, destroyBuffer>;
using Memory = DeviceHandle<VkDeviceMemory, freeMemory>;

}  // namespace steadyxr::layer
