// Small RAII helpers for Vulkan handles owned by the filter core.
#pragma once

#include <vulkan/vulkan.h>

#include <utility>

namespace steadyxr::core::detail {

template <typename T>
using DestroyFn = void (*)(VkDevice, T, const VkAllocationCallbacks*);

// Owns one device-child handle; every vkDestroy*/vkFree* used here has the same signature.
template <typename T>
class Unique {
 public:
  Unique() = default;
  Unique(VkDevice device, T handle, DestroyFn<T> destroy)
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

}  // namespace steadyxr::core::detail
