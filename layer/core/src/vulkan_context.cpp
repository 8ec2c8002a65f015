#include "steadyxr/core/vulkan_context.h"

#include <cstring>
#include <mutex>

#include "filter_pipelines.h"

namespace steadyxr::core {

struct VulkanContext::Impl {
  bool owned = false;
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physicalDevice = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  uint32_t queueFamily = 0;
  VkPhysicalDeviceProperties props{};
  VkPhysicalDeviceMemoryProperties memProps{};
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;

  mutable std::mutex messagesMutex;  // the validation callback may run on any thread
  std::vector<std::string> messages;

  std::mutex pipelineStoreMutex;  // filters may be made on more than one thread
  std::unique_ptr<detail::PipelineStore> pipelineStore;

  ~Impl() {
    pipelineStore.reset();  // its pipelines and layouts go before the device, borrowed or not
    if (!owned) return;     // borrowed handles belong to the application
    if (device) {
      vkDeviceWaitIdle(device);
      vkDestroyDevice(device, nullptr);
    }
    if (messenger) {
      auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
          vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"));
      if (destroy) destroy(instance, messenger, nullptr);
    }
    if (instance) vkDestroyInstance(instance, nullptr);
  }

  static VKAPI_ATTR VkBool32 VKAPI_CALL onMessage(VkDebugUtilsMessageSeverityFlagBitsEXT,
                                                  VkDebugUtilsMessageTypeFlagsEXT,
                                                  const VkDebugUtilsMessengerCallbackDataEXT* data,
                                                  void* user) {
    auto* self = static_cast<Impl*>(user);
    std::lock_guard lock(self->messagesMutex);
    self->messages.emplace_back(data && data->pMessage ? data->pMessage : "(no message)");
    return VK_FALSE;
  }
};

namespace {

bool hasLayer(const char* name) {
  uint32_t n = 0;
  vkEnumerateInstanceLayerProperties(&n, nullptr);
  std::vector<VkLayerProperties> layers(n);
  vkEnumerateInstanceLayerProperties(&n, layers.data());
  for (const auto& l : layers) {
    if (std::strcmp(l.layerName, name) == 0) return true;
  }
  return false;
}

bool hasInstanceExtension(const char* name) {
  uint32_t n = 0;
  vkEnumerateInstanceExtensionProperties(nullptr, &n, nullptr);
  std::vector<VkExtensionProperties> exts(n);
  vkEnumerateInstanceExtensionProperties(nullptr, &n, exts.data());
  for (const auto& e : exts) {
    if (std::strcmp(e.extensionName, name) == 0) return true;
  }
  return false;
}

void setError(std::string* error, std::string msg) {
  if (error) *error = std::move(msg);
}

}  // namespace

VulkanContext::VulkanContext(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
VulkanContext::~VulkanContext() = default;

std::unique_ptr<VulkanContext> VulkanContext::createOwned(const OwnedContextOptions& options,
                                                          std::string* error) {
  auto impl = std::make_unique<Impl>();
  impl->owned = true;

  VkApplicationInfo app{};

  app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
  app.pApplicationName = options.applicationName.c_str();
  app.pEngineName = "steadyxr";
  app.apiVersion = VK_API_VERSION_1_1;

  std::vector<const char*> layers;
  std::vector<const char*> exts;
  const bool validation = options.enableValidation;
  if (validation) {
    if (!hasLayer("VK_LAYER_KHRONOS_validation")) {
      setError(error, "VK_LAYER_KHRONOS_validation requested but not installed");
      return nullptr;
    }
    layers.push_back("VK_LAYER_KHRONOS_validation");
    if (hasInstanceExtension(VK_EXT_DEBUG_UTILS_EXTENSION_NAME))
      exts.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  }
  VkDebugUtilsMessengerCreateInfoEXT dbg{};
  dbg.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
  dbg.messageSeverity =
      VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  dbg.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                    VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                    VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  dbg.pfnUserCallback = &Impl::onMessage;
  dbg.pUserData = impl.get();

  VkInstanceCreateInfo ici{};

  ici.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
  ici.pApplicationInfo = &app;
  ici.enabledLayerCount = static_cast<uint32_t>(layers.size());
  ici.ppEnabledLayerNames = layers.data();
  ici.enabledExtensionCount = static_cast<uint32_t>(exts.size());
  ici.ppEnabledExtensionNames = exts.data();
  if (!exts.empty()) ici.pNext = &dbg;  // also catches messages from create/destroy instance
  if (VkResult r = vkCreateInstance(&ici, nullptr, &impl->instance); r != VK_SUCCESS) {
    setError(error, "vkCreateInstance failed: " + std::to_string(r));
    return nullptr;
  }
  if (!exts.empty()) {
    auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(impl->instance, "vkCreateDebugUtilsMessengerEXT"));
    if (create) create(impl->instance, &dbg, nullptr, &impl->messenger);
  }

  uint32_t n = 0;
  vkEnumeratePhysicalDevices(impl->instance, &n, nullptr);
  std::vector<VkPhysicalDevice> devices(n);
  vkEnumeratePhysicalDevices(impl->instance, &n, devices.data());
  int best = -1;
  uint32_t bestFamily = 0;
  int bestScore = -1;
  for (size_t i = 0; i < devices.size(); ++i) {
    VkPhysicalDeviceProperties p;
    vkGetPhysicalDeviceProperties(devices[i], &p);
    if (p.apiVersion < VK_API_VERSION_1_1) continue;
    uint32_t qn = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(devices[i], &qn, nullptr);
    std::vector<VkQueueFamilyProperties> qf(qn);
    vkGetPhysicalDeviceQueueFamilyProperties(devices[i], &qn, qf.data());
    for (uint32_t f = 0; f < qn; ++f) {
      if (!(qf[f].queueFlags & VK_QUEUE_COMPUTE_BIT)) continue;
      int score = 1;
      const bool cpu = p.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
      if (options.preferCpuDevice == cpu) score += 10;
      if (qf[f].timestampValidBits > 0) score += 1;
      if (score > bestScore) {
        bestScore = score;
        best = static_cast<int>(i);
        bestFamily = f;
      }
      break;
    }
  }
  if (best < 0) {
    setError(error, "no Vulkan 1.1 device with a compute queue");
    return nullptr;
  }
  impl->physicalDevice = devices[static_cast<size_t>(best)];
  impl->queueFamily = bestFamily;

  const float prio = 1.0f;
  VkDeviceQueueCreateInfo qci{};
  qci.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
  qci.queueFamilyIndex = bestFamily;
  qci.queueCount = 1;
  qci.pQueuePriorities = &prio;
  VkDeviceCreateInfo dci{};
  dci.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qci;
  if (VkResult r = vkCreateDevice(impl->physicalDevice, &dci, nullptr, &impl->device); r != VK_SUCCESS) {
    setError(error, "vkCreateDevice failed: " + std::to_string(r));
    return nullptr;
  }
  vkGetDeviceQueue(impl->device, bestFamily, 0, &impl->queue);
  vkGetPhysicalDeviceProperties(impl->physicalDevice, &impl->props);
  vkGetPhysicalDeviceMemoryProperties(impl->physicalDevice, &impl->memProps);
  return std::unique_ptr<VulkanContext>(new VulkanContext(std::move(impl)));
}

std::unique_ptr<VulkanContext> VulkanContext::borrow(const BorrowedHandles& h, std::string* error) {
  if (!h.instance || !h.physicalDevice || !h.device) {
    setError(error, "borrow: instance, physical device and device are required");
    return nullptr;
  }
  if (h.apiVersion < VK_API_VERSION_1_1) {
    setError(error, "borrow: the application's instance must be Vulkan 1.1 or newer");
    return nullptr;
  }
  auto impl = std::make_unique<Impl>();
  impl->owned = false;
  impl->instance = h.instance;
  impl->physicalDevice = h.physicalDevice;
  impl->device = h.device;
  impl->queueFamily = h.queueFamilyIndex;
  uint32_t qn = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(h.physicalDevice, &qn, nullptr);
  std::vector<VkQueueFamilyProperties> qf(qn);
  vkGetPhysicalDeviceQueueFamilyProperties(h.physicalDevice, &qn, qf.data());
  if (h.queueFamilyIndex >= qn || !(qf[h.queueFamilyIndex].queueFlags & VK_QUEUE_COMPUTE_BIT) ||
      h.queueIndex >= qf[h.queueFamilyIndex].queueCount) {
    setError(error, "borrow: the queue family has no compute support or the queue index is out of range");
    return nullptr;
  }
  vkGetDeviceQueue(h.device, h.queueFamilyIndex, h.queueIndex, &impl->queue);
  vkGetPhysicalDeviceProperties(h.physicalDevice, &impl->props);
  vkGetPhysicalDeviceMemoryProperties(h.physicalDevice, &impl->memProps);
  return std::unique_ptr<VulkanContext>(new VulkanContext(std::move(impl)));
}

detail::PipelineStore* VulkanContext::pipelineStore(std::string* error) {
  std::lock_guard lock(impl_->pipelineStoreMutex);
  if (!impl_->pipelineStore) {
    auto store = std::make_unique<detail::PipelineStore>(impl_->device);
    if (!store->init(error)) return nullptr;
    impl_->pipelineStore = std::move(store);
  }
  return impl_->pipelineStore.get();
}

VkInstance VulkanContext::instance() const {
  return impl_->instance;
}
VkPhysicalDevice VulkanContext::physicalDevice() const {
  return impl_->physicalDevice;
}
VkDevice VulkanContext::device() const {
  return impl_->device;
}
VkQueue VulkanContext::queue() const {
  return impl_->queue;
}
uint32_t VulkanContext::queueFamilyIndex() const {
  return impl_->queueFamily;
}
bool VulkanContext::owned() const {
  return impl_->owned;
}
const VkPhysicalDeviceProperties& VulkanContext::properties() const {
  return impl_->props;
}

uint32_t VulkanContext::findMemoryType(uint32_t typeBits, VkMemoryPropertyFlags required) const {
  for (uint32_t i = 0; i < impl_->memProps.memoryTypeCount; ++i) {
    if ((typeBits & (1u << i)) && (impl_->memProps.memoryTypes[i].propertyFlags & required) == required)
      return i;
  }
  return UINT32_MAX;
}

uint32_t VulkanContext::findMemoryType(uint32_t typeBits, VkMemoryPropertyFlags required,
                                       VkMemoryPropertyFlags preferred) const {
  const uint32_t best = findMemoryType(typeBits, required | preferred);
  return best != UINT32_MAX ? best : findMemoryType(typeBits, required);
}

bool VulkanContext::isCpuDevice() const {
  return impl_->props.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
}

uint32_t VulkanContext::validationMessageCount() const {
  std::lock_guard lock(impl_->messagesMutex);
  return static_cast<uint32_t>(impl_->messages.size());
}

std::vector<std::string> VulkanContext::validationMessages() const {
  std::lock_guard lock(impl_->messagesMutex);
  return impl_->messages;
}

}  // namespace steadyxr::core
