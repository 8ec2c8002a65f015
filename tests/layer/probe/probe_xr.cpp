#include "probe_xr.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <thread>

namespace probe {
namespace {

template <typename T>
T xrStruct(XrStructureType type) {
  T v{};
  v.type = type;
  return v;
}

template <typename T>
T vkStruct(VkStructureType type) {
  T v{};
  v.sType = type;
  return v;
}

template <typename F>
F xrFn(XrInstance instance, const char* name) {
  PFN_xrVoidFunction f = nullptr;
  xrGetInstanceProcAddr(instance, name, &f);
  return reinterpret_cast<F>(f);
}

std::string resultName(XrInstance instance, XrResult r) {
  char buf[XR_MAX_RESULT_STRING_SIZE] = {};
  if (XR_FAILED(xrResultToString(instance, r, buf)))
    std::snprintf(buf, sizeof buf, "%d", static_cast<int>(r));
  return buf;
}

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::istringstream in(s);
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

uint16_t toHalf(float f) {  // IEEE 754 binary16, round to nearest (values here are in [0, 1])
  uint32_t x;
  std::memcpy(&x, &f, 4);
  const uint32_t sign = (x >> 16) & 0x8000u;
  const int exp = static_cast<int>((x >> 23) & 0xff) - 127 + 15;
  uint32_t mant = x & 0x7fffffu;
  if (exp <= 0) return static_cast<uint16_t>(sign);
  if (exp >= 31) return static_cast<uint16_t>(sign | 0x7c00u);
  mant += 0x1000u;  // round
  if (mant & 0x800000u) return static_cast<uint16_t>(sign | ((exp + 1) << 10));
  return static_cast<uint16_t>(sign | (exp << 10) | (mant >> 13));
}

}  // namespace

CaseSpec caseSpec(const std::string& name) {
  CaseSpec s;
  if (name == "array") s.kind = CaseKind::Array;
  if (name == "sbs") s.kind = CaseKind::SideBySide;
  if (name == "alpha") {  // premultiplied alpha blending: filtered, alpha carried through
    s.flags = XR_COMPOSITION_LAYER_BLEND_TEXTURE_SOURCE_ALPHA_BIT;
    s.translucent = true;
  }
  if (name == "unpremultiplied") {  // straight alpha: passed through (layer/xr/README.md)
    s.flags =
        XR_COMPOSITION_LAYER_BLEND_TEXTURE_SOURCE_ALPHA_BIT | XR_COMPOSITION_LAYER_UNPREMULTIPLIED_ALPHA_BIT;
    s.translucent = true;
    s.expectFiltered = false;
    s.expectReason = "unpremultiplied_alpha";
  }
  if (name == "depth") s.depth = true;
  if (name == "multi") s.multi = true;
  if (name == "unorm") s.format = VK_FORMAT_R8G8B8A8_UNORM;
  if (name == "fp16") {
    s.format = VK_FORMAT_R16G16B16A16_SFLOAT;
    s.dumpable = false;  // the layer dumps 8-bit images only
  }
  if (name == "resize") s.resize = true;
  if (name == "invalid") {  // a side-by-side swapchain, then the invalid calls
    s.kind = CaseKind::Invalid;
    s.format = VK_FORMAT_R8G8B8A8_UNORM;
  }
  return s;
}

struct Xr::Swapchain {
  XrSwapchain handle = XR_NULL_HANDLE;
  std::vector<VkImage> images;
  VkFormat format = VK_FORMAT_UNDEFINED;
  uint32_t width = 0, height = 0, layers = 1;
  bool depth = false;
};

Xr::~Xr() {
  if (pool_) vkDestroyCommandPool(device_, pool_, nullptr);
  if (device_) vkDestroyDevice(device_, nullptr);
  if (vkInstance_) vkDestroyInstance(vkInstance_, nullptr);
  if (instance_) xrDestroyInstance(instance_);
}

bool Xr::init(Api api) {
  api_ = api;
  uint32_t n = 0;
  xrEnumerateInstanceExtensionProperties(nullptr, 0, &n, nullptr);
  std::vector<XrExtensionProperties> props(n, xrStruct<XrExtensionProperties>(XR_TYPE_EXTENSION_PROPERTIES));
  xrEnumerateInstanceExtensionProperties(nullptr, n, &n, props.data());
  std::vector<const char*> exts = {api == Api::V2 ? XR_KHR_VULKAN_ENABLE2_EXTENSION_NAME
                                                  : XR_KHR_VULKAN_ENABLE_EXTENSION_NAME};
  for (const auto& p : props)
    if (std::strcmp(p.extensionName, XR_KHR_COMPOSITION_LAYER_DEPTH_EXTENSION_NAME) == 0)
      depthExtension_ = true;
  if (depthExtension_) exts.push_back(XR_KHR_COMPOSITION_LAYER_DEPTH_EXTENSION_NAME);
  auto ci = xrStruct<XrInstanceCreateInfo>(XR_TYPE_INSTANCE_CREATE_INFO);
  std::strcpy(ci.applicationInfo.applicationName, "steadyxr-probe");
  ci.applicationInfo.apiVersion = XR_MAKE_VERSION(1, 0, 0);
  ci.enabledExtensionCount = static_cast<uint32_t>(exts.size());
  ci.enabledExtensionNames = exts.data();
  XrResult r = xrCreateInstance(&ci, &instance_);
  if (XR_FAILED(r)) return error = "xrCreateInstance: " + std::to_string(r), false;
  auto gi = xrStruct<XrSystemGetInfo>(XR_TYPE_SYSTEM_GET_INFO);
  gi.formFactor = XR_FORM_FACTOR_HEAD_MOUNTED_DISPLAY;
  if (XR_FAILED(r = xrGetSystem(instance_, &gi, &system_)))
    return error = "xrGetSystem " + resultName(instance_, r), false;
  auto sp = xrStruct<XrSystemProperties>(XR_TYPE_SYSTEM_PROPERTIES);
  if (XR_SUCCEEDED(xrGetSystemProperties(instance_, system_, &sp)))
    maxLayers_ = sp.graphicsProperties.maxLayerCount;
  if (!(api == Api::V2 ? initVulkanV2() : initVulkanV1())) return false;
  VkPhysicalDeviceProperties pp{};
  vkGetPhysicalDeviceProperties(physical_, &pp);
  deviceName = pp.deviceName;
  vkGetDeviceQueue(device_, family_, 0, &queue_);
  auto pci = vkStruct<VkCommandPoolCreateInfo>(VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO);
  pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pci.queueFamilyIndex = family_;
  return vkCreateCommandPool(device_, &pci, nullptr, &pool_) == VK_SUCCESS || (error = "command pool", false);
}

namespace {
uint32_t pickFamily(VkPhysicalDevice pd) {
  uint32_t n = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(pd, &n, nullptr);
  std::vector<VkQueueFamilyProperties> f(n);
  vkGetPhysicalDeviceQueueFamilyProperties(pd, &n, f.data());
  for (uint32_t i = 0; i < n; ++i)
    if ((f[i].queueFlags & VK_QUEUE_GRAPHICS_BIT) && (f[i].queueFlags & VK_QUEUE_COMPUTE_BIT)) return i;
  return 0;
}
}  // namespace

bool Xr::initVulkanV2() {
  auto req = xrStruct<XrGraphicsRequirementsVulkan2KHR>(XR_TYPE_GRAPHICS_REQUIREMENTS_VULKAN2_KHR);
  xrFn<PFN_xrGetVulkanGraphicsRequirements2KHR>(instance_, "xrGetVulkanGraphicsRequirements2KHR")(
      instance_, system_, &req);
  auto app = vkStruct<VkApplicationInfo>(VK_STRUCTURE_TYPE_APPLICATION_INFO);
  app.pApplicationName = "steadyxr-probe";
  app.apiVersion = VK_API_VERSION_1_1;
  instanceApiVersion = app.apiVersion;
  auto ici = vkStruct<VkInstanceCreateInfo>(VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO);
  ici.pApplicationInfo = &app;
  auto xci = xrStruct<XrVulkanInstanceCreateInfoKHR>(XR_TYPE_VULKAN_INSTANCE_CREATE_INFO_KHR);
  xci.systemId = system_;
  xci.pfnGetInstanceProcAddr = vkGetInstanceProcAddr;
  xci.vulkanCreateInfo = &ici;
  VkResult vr = VK_SUCCESS;
  auto createInstance = xrFn<PFN_xrCreateVulkanInstanceKHR>(instance_, "xrCreateVulkanInstanceKHR");
  XrResult r = createInstance(instance_, &xci, &vkInstance_, &vr);
  if (XR_FAILED(r) || vr != VK_SUCCESS)
    return error = "xrCreateVulkanInstanceKHR " + resultName(instance_, r), false;
  auto dgi = xrStruct<XrVulkanGraphicsDeviceGetInfoKHR>(XR_TYPE_VULKAN_GRAPHICS_DEVICE_GET_INFO_KHR);
  dgi.systemId = system_;
  dgi.vulkanInstance = vkInstance_;
  xrFn<PFN_xrGetVulkanGraphicsDevice2KHR>(instance_, "xrGetVulkanGraphicsDevice2KHR")(instance_, &dgi,
                                                                                      &physical_);
  family_ = pickFamily(physical_);
  const float prio = 1.0f;
  auto q = vkStruct<VkDeviceQueueCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO);
  q.queueFamilyIndex = family_;
  q.queueCount = 1;
  q.pQueuePriorities = &prio;
  auto dci = vkStruct<VkDeviceCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO);
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &q;
  auto xdci = xrStruct<XrVulkanDeviceCreateInfoKHR>(XR_TYPE_VULKAN_DEVICE_CREATE_INFO_KHR);
  xdci.systemId = system_;
  xdci.pfnGetInstanceProcAddr = vkGetInstanceProcAddr;
  xdci.vulkanPhysicalDevice = physical_;
  xdci.vulkanCreateInfo = &dci;
  r = xrFn<PFN_xrCreateVulkanDeviceKHR>(instance_, "xrCreateVulkanDeviceKHR")(instance_, &xdci, &device_,
                                                                              &vr);
  if (XR_FAILED(r) || vr != VK_SUCCESS)
    return error = "xrCreateVulkanDeviceKHR " + resultName(instance_, r), false;
  enabledDeviceExtensions = "(chosen by the runtime)";
  return true;
}

// XR_KHR_vulkan_enable: the app creates instance and device itself with the extensions the
// runtime lists; as Proton's DXVK does, with a Vulkan 1.3 instance. Extensions the device
// lacks are left out (Monado lists VK_KHR_external_semaphore_fd/fence_fd, lavapipe has
// neither), and printed, so a failure below can be told apart.
bool Xr::initVulkanV1() {
  auto req = xrStruct<XrGraphicsRequirementsVulkanKHR>(XR_TYPE_GRAPHICS_REQUIREMENTS_VULKAN_KHR);
  xrFn<PFN_xrGetVulkanGraphicsRequirementsKHR>(instance_, "xrGetVulkanGraphicsRequirementsKHR")(
      instance_, system_, &req);
  auto listed = [&](const char* fn, bool device) {
    auto get = xrFn<PFN_xrGetVulkanInstanceExtensionsKHR>(instance_, fn);  // same signature
    uint32_t n = 0;
    get(instance_, system_, 0, &n, nullptr);
    std::string s(n, '\0');
    get(instance_, system_, n, &n, s.data());
    (void)device;
    return split(s.c_str());
  };
  uint32_t n = 0;
  vkEnumerateInstanceExtensionProperties(nullptr, &n, nullptr);
  std::vector<VkExtensionProperties> have(n);
  vkEnumerateInstanceExtensionProperties(nullptr, &n, have.data());
  const std::vector<std::string> instExts = listed("xrGetVulkanInstanceExtensionsKHR", false);
  std::vector<const char*> use;
  for (const auto& e : instExts)
    if (std::any_of(have.begin(), have.end(),
                    [&](const VkExtensionProperties& p) { return e == p.extensionName; }))
      use.push_back(e.c_str());
  auto app = vkStruct<VkApplicationInfo>(VK_STRUCTURE_TYPE_APPLICATION_INFO);
  app.pApplicationName = "steadyxr-probe";
  app.apiVersion = VK_API_VERSION_1_3;
  instanceApiVersion = app.apiVersion;
  auto ici = vkStruct<VkInstanceCreateInfo>(VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO);
  ici.pApplicationInfo = &app;
  ici.enabledExtensionCount = static_cast<uint32_t>(use.size());
  ici.ppEnabledExtensionNames = use.data();
  if (vkCreateInstance(&ici, nullptr, &vkInstance_) != VK_SUCCESS) return error = "vkCreateInstance", false;
  XrResult r = xrFn<PFN_xrGetVulkanGraphicsDeviceKHR>(instance_, "xrGetVulkanGraphicsDeviceKHR")(
      instance_, system_, vkInstance_, &physical_);
  if (XR_FAILED(r)) return error = "xrGetVulkanGraphicsDeviceKHR " + resultName(instance_, r), false;
  vkEnumerateDeviceExtensionProperties(physical_, nullptr, &n, nullptr);
  std::vector<VkExtensionProperties> devHave(n);
  vkEnumerateDeviceExtensionProperties(physical_, nullptr, &n, devHave.data());
  const std::vector<std::string> devExts = listed("xrGetVulkanDeviceExtensionsKHR", true);
  std::vector<const char*> devUse;
  std::string skipped;
  for (const auto& e : devExts) {
    if (std::any_of(devHave.begin(), devHave.end(),
                    [&](const VkExtensionProperties& p) { return e == p.extensionName; })) {
      devUse.push_back(e.c_str());
      enabledDeviceExtensions += e + " ";
    } else {
      skipped += e + " ";
    }
  }
  enabledDeviceExtensions +=
      "(listed but missing on the device: " + (skipped.empty() ? "none" : skipped) + ")";
  family_ = pickFamily(physical_);
  const float prio = 1.0f;
  auto q = vkStruct<VkDeviceQueueCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO);
  q.queueFamilyIndex = family_;
  q.queueCount = 1;
  q.pQueuePriorities = &prio;
  auto dci = vkStruct<VkDeviceCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO);
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &q;
  dci.enabledExtensionCount = static_cast<uint32_t>(devUse.size());
  dci.ppEnabledExtensionNames = devUse.data();
  if (vkCreateDevice(physical_, &dci, nullptr, &device_) != VK_SUCCESS)
    return error = "vkCreateDevice", false;
  return true;
}

bool Xr::pollUntil(XrSessionState want, XrSession session, int timeoutMs) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeoutMs);
  while (std::chrono::steady_clock::now() < end) {
    auto ev = xrStruct<XrEventDataBuffer>(XR_TYPE_EVENT_DATA_BUFFER);
    while (xrPollEvent(instance_, &ev) == XR_SUCCESS) {
      if (ev.type == XR_TYPE_EVENT_DATA_SESSION_STATE_CHANGED) {
        const auto& sc = *reinterpret_cast<XrEventDataSessionStateChanged*>(&ev);
        if (sc.session == session && sc.state == want) return true;
      }
      ev = xrStruct<XrEventDataBuffer>(XR_TYPE_EVENT_DATA_BUFFER);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return false;
}

bool Xr::createSwapchain(XrSession s, VkFormat format, uint32_t w, uint32_t h, uint32_t layers, bool depth,
                         Swapchain* out) {
  auto ci = xrStruct<XrSwapchainCreateInfo>(XR_TYPE_SWAPCHAIN_CREATE_INFO);
  ci.usageFlags =
      (depth ? XR_SWAPCHAIN_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT : XR_SWAPCHAIN_USAGE_COLOR_ATTACHMENT_BIT) |
      XR_SWAPCHAIN_USAGE_TRANSFER_DST_BIT;
  ci.format = format;
  ci.sampleCount = 1;
  ci.width = w;
  ci.height = h;
  ci.faceCount = 1;
  ci.arraySize = layers;
  ci.mipCount = 1;
  if (XR_FAILED(xrCreateSwapchain(s, &ci, &out->handle))) return false;
  uint32_t n = 0;
  xrEnumerateSwapchainImages(out->handle, 0, &n, nullptr);
  std::vector<XrSwapchainImageVulkanKHR> imgs(
      n, xrStruct<XrSwapchainImageVulkanKHR>(XR_TYPE_SWAPCHAIN_IMAGE_VULKAN_KHR));
  xrEnumerateSwapchainImages(out->handle, n, &n, reinterpret_cast<XrSwapchainImageBaseHeader*>(imgs.data()));
  out->images.clear();
  for (const auto& i : imgs) out->images.push_back(i.image);
  out->format = format;
  out->width = w;
  out->height = h;
  out->layers = layers;
  out->depth = depth;
  return true;
}

// Acquire, wait, fill every layer with a moving pattern (colour with edges; alpha varied per
// pixel when translucent, premultiplied into the colour), release.
bool Xr::render(Swapchain& sc, uint32_t w, uint32_t h, uint32_t layers, int frame, bool translucent) {
  uint32_t index = 0;
  if (XR_FAILED(xrAcquireSwapchainImage(sc.handle, nullptr, &index))) return false;
  auto wi = xrStruct<XrSwapchainImageWaitInfo>(XR_TYPE_SWAPCHAIN_IMAGE_WAIT_INFO);
  wi.timeout = XR_INFINITE_DURATION;
  if (XR_FAILED(xrWaitSwapchainImage(sc.handle, &wi))) return false;
  const bool half = sc.format == VK_FORMAT_R16G16B16A16_SFLOAT;
  const VkDeviceSize px = half ? 8 : 4, size = VkDeviceSize{w} * h * layers * px;
  VkBuffer buf = VK_NULL_HANDLE;
  VkDeviceMemory mem = VK_NULL_HANDLE;
  auto bci = vkStruct<VkBufferCreateInfo>(VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO);
  bci.size = size;
  bci.usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
  vkCreateBuffer(device_, &bci, nullptr, &buf);
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(device_, buf, &req);
  VkPhysicalDeviceMemoryProperties mp;
  vkGetPhysicalDeviceMemoryProperties(physical_, &mp);
  auto mai = vkStruct<VkMemoryAllocateInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO);
  mai.allocationSize = req.size;
  for (uint32_t i = 0; i < mp.memoryTypeCount; ++i)
    if ((req.memoryTypeBits & (1u << i)) &&
        (mp.memoryTypes[i].propertyFlags &
         (VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT)) ==
            (VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT)) {
      mai.memoryTypeIndex = i;
      break;
    }
  vkAllocateMemory(device_, &mai, nullptr, &mem);
  vkBindBufferMemory(device_, buf, mem, 0);
  if (!sc.depth) {
    void* mapped = nullptr;
    vkMapMemory(device_, mem, 0, size, 0, &mapped);
    auto* b8 = static_cast<uint8_t*>(mapped);
    auto* b16 = static_cast<uint16_t*>(mapped);
    for (uint32_t l = 0; l < layers; ++l)
      for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
          const size_t i = (size_t{l} * h + y) * w + x;
          const bool edge = ((x + uint32_t(frame)) / 6 + y / 6 + l) % 2 != 0;
          const float a = translucent ? float((x * 7 + y * 3 + uint32_t(frame)) % 256) / 255.0f : 1.0f;
          const float c[4] = {(edge ? 0.9f : 0.1f) * a, 0.5f * a, (edge ? 0.2f : 0.8f) * a, a};
          for (int k = 0; k < 4; ++k) {
            if (half)
              b16[i * 4 + k] = toHalf(c[k]);
            else
              b8[i * 4 + k] = static_cast<uint8_t>(std::lround(c[k] * 255.0f));
          }
        }
    vkUnmapMemory(device_, mem);
  }
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  auto cai = vkStruct<VkCommandBufferAllocateInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO);
  cai.commandPool = pool_;
  cai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  cai.commandBufferCount = 1;
  vkAllocateCommandBuffers(device_, &cai, &cmd);
  auto begin = vkStruct<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  vkBeginCommandBuffer(cmd, &begin);
  const VkImageAspectFlags aspect = sc.depth ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT;
  const VkImageLayout attach =
      sc.depth ? VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL : VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
  auto b = vkStruct<VkImageMemoryBarrier>(VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER);
  b.srcAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
  b.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  b.oldLayout = attach;
  b.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
  b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.image = sc.images[index];
  b.subresourceRange = {aspect, 0, 1, 0, layers};
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr,
                       0, nullptr, 1, &b);
  if (sc.depth) {
    const VkClearDepthStencilValue v{0.5f, 0};
    vkCmdClearDepthStencilImage(cmd, sc.images[index], VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &v, 1,
                                &b.subresourceRange);
  } else {
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, layers};
    region.imageExtent = {w, h, 1};
    vkCmdCopyBufferToImage(cmd, buf, sc.images[index], VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
  }
  b.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  b.dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
  b.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
  b.newLayout = attach;  // what the Vulkan binding requires at release
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 0, nullptr,
                       0, nullptr, 1, &b);
  vkEndCommandBuffer(cmd);
  auto si = vkStruct<VkSubmitInfo>(VK_STRUCTURE_TYPE_SUBMIT_INFO);
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cmd;
  vkQueueSubmit(queue_, 1, &si, VK_NULL_HANDLE);
  vkQueueWaitIdle(queue_);
  vkFreeCommandBuffers(device_, pool_, 1, &cmd);
  vkDestroyBuffer(device_, buf, nullptr);
  vkFreeMemory(device_, mem, nullptr);
  return XR_SUCCEEDED(xrReleaseSwapchainImage(sc.handle, nullptr));
}

// The invalid xrEndFrame calls of issue 15; each result is printed so that a run without the
// layer can be compared (tests/layer/probe/run_probe.sh). A frame the call did not end is
// ended with no layers.
std::string Xr::invalidCalls(XrSession session, XrSpace space, Swapchain& sc) {
  std::string out;
  auto views = std::array<XrCompositionLayerProjectionView, 3>{};
  for (uint32_t v = 0; v < 3; ++v) {
    views[v] = xrStruct<XrCompositionLayerProjectionView>(XR_TYPE_COMPOSITION_LAYER_PROJECTION_VIEW);
    views[v].pose.orientation.w = 1.0f;
    views[v].fov = {-0.7f, 0.7f, 0.7f, -0.7f};
    views[v].subImage.swapchain = sc.handle;
    views[v].subImage.imageRect = {{int32_t(v % 2 * (sc.width / 2)), 0},
                                   {int32_t(sc.width / 2), int32_t(sc.height)}};
  }
  auto proj = xrStruct<XrCompositionLayerProjection>(XR_TYPE_COMPOSITION_LAYER_PROJECTION);
  proj.space = space;
  proj.viewCount = 2;
  proj.views = views.data();
  auto nullViews = proj;
  nullViews.views = nullptr;
  auto threeViews = proj;
  threeViews.viewCount = 3;
  const auto* good = reinterpret_cast<const XrCompositionLayerBaseHeader*>(&proj);
  std::vector<const XrCompositionLayerBaseHeader*> tooMany(maxLayers_ + 1, good);
  const XrCompositionLayerBaseHeader* nullEntry[] = {nullptr};
  const XrCompositionLayerBaseHeader* nullViewsLayer[] = {
      reinterpret_cast<const XrCompositionLayerBaseHeader*>(&nullViews)};
  const XrCompositionLayerBaseHeader* threeViewsLayer[] = {
      reinterpret_cast<const XrCompositionLayerBaseHeader*>(&threeViews)};
  struct Call {
    const char* name;
    uint32_t count;
    const XrCompositionLayerBaseHeader* const* layers;
  };
  const Call calls[] = {{"layers_null", 1, nullptr},
                        {"layer_entry_null", 1, nullEntry},
                        {"layer_count_over_max", maxLayers_ + 1, tooMany.data()},
                        {"views_null", 1, nullViewsLayer},
                        {"view_count_3", 1, threeViewsLayer}};
  for (const Call& c : calls) {
    auto fs = xrStruct<XrFrameState>(XR_TYPE_FRAME_STATE);
    xrWaitFrame(session, nullptr, &fs);
    xrBeginFrame(session, nullptr);
    if (!render(sc, sc.width, sc.height, 1, 0, false)) return "render failed";
    auto ei = xrStruct<XrFrameEndInfo>(XR_TYPE_FRAME_END_INFO);
    ei.displayTime = fs.predictedDisplayTime;
    ei.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
    ei.layerCount = c.count;
    ei.layers = c.layers;
    const XrResult r = xrEndFrame(session, &ei);
    out += std::string(" ") + c.name + "=" + resultName(instance_, r);
    if (XR_FAILED(r)) {
      ei.layerCount = 0;
      ei.layers = nullptr;
      xrEndFrame(session, &ei);
    }
  }
  if (api_ == Api::V2) {  // xrCreateVulkanInstanceKHR without a VkInstanceCreateInfo
    auto xci = xrStruct<XrVulkanInstanceCreateInfoKHR>(XR_TYPE_VULKAN_INSTANCE_CREATE_INFO_KHR);
    xci.systemId = system_;
    xci.pfnGetInstanceProcAddr = vkGetInstanceProcAddr;
    VkInstance vi = VK_NULL_HANDLE;
    VkResult vr = VK_SUCCESS;
    const XrResult r = xrFn<PFN_xrCreateVulkanInstanceKHR>(instance_, "xrCreateVulkanInstanceKHR")(
        instance_, &xci, &vi, &vr);
    out += " vulkan_create_info_null=" + resultName(instance_, r);
    if (XR_SUCCEEDED(r) && vi) vkDestroyInstance(vi, nullptr);
  }
  return out;
}

CaseResult Xr::runCase(const CaseSpec& spec, int frames) {
  CaseResult res;
  auto binding = xrStruct<XrGraphicsBindingVulkanKHR>(XR_TYPE_GRAPHICS_BINDING_VULKAN_KHR);
  binding.instance = vkInstance_;
  binding.physicalDevice = physical_;
  binding.device = device_;
  binding.queueFamilyIndex = family_;
  auto sci = xrStruct<XrSessionCreateInfo>(XR_TYPE_SESSION_CREATE_INFO);
  sci.next = &binding;
  sci.systemId = system_;
  XrSession session = XR_NULL_HANDLE;
  XrResult r = xrCreateSession(instance_, &sci, &session);
  if (XR_FAILED(r)) return res.detail = " xrCreateSession " + resultName(instance_, r), res;
  std::vector<Swapchain> color, depth;
  Swapchain quad;
  XrSpace space = XR_NULL_HANDLE;
  auto finish = [&](bool ok, const std::string& detail) {
    for (auto& s : color) xrDestroySwapchain(s.handle);
    for (auto& s : depth) xrDestroySwapchain(s.handle);
    if (quad.handle) xrDestroySwapchain(quad.handle);
    if (space) xrDestroySpace(space);
    if (XR_SUCCEEDED(xrRequestExitSession(session))) {
      // Frames until the runtime stops the session, as an app does.
      for (int i = 0; i < 200; ++i) {
        if (pollUntil(XR_SESSION_STATE_STOPPING, session, 5)) break;
        auto fs = xrStruct<XrFrameState>(XR_TYPE_FRAME_STATE);
        if (XR_FAILED(xrWaitFrame(session, nullptr, &fs))) break;
        xrBeginFrame(session, nullptr);
        auto ei = xrStruct<XrFrameEndInfo>(XR_TYPE_FRAME_END_INFO);
        ei.displayTime = fs.predictedDisplayTime;
        ei.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
        xrEndFrame(session, &ei);
      }
      xrEndSession(session);
    }
    xrDestroySession(session);  // the layer logs its session summary here
    res.ok = ok;
    res.detail = detail;
    return res;
  };
  if (!pollUntil(XR_SESSION_STATE_READY, session, 5000)) return finish(false, " session never READY");
  auto bi = xrStruct<XrSessionBeginInfo>(XR_TYPE_SESSION_BEGIN_INFO);
  bi.primaryViewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
  if (XR_FAILED(r = xrBeginSession(session, &bi)))
    return finish(false, " xrBeginSession " + resultName(instance_, r));
  auto rci = xrStruct<XrReferenceSpaceCreateInfo>(XR_TYPE_REFERENCE_SPACE_CREATE_INFO);
  rci.referenceSpaceType = XR_REFERENCE_SPACE_TYPE_LOCAL;
  rci.poseInReferenceSpace.orientation.w = 1.0f;
  xrCreateReferenceSpace(session, &rci, &space);

  uint32_t nf = 0;
  xrEnumerateSwapchainFormats(session, 0, &nf, nullptr);
  std::vector<int64_t> formats(nf);
  xrEnumerateSwapchainFormats(session, nf, &nf, formats.data());
  auto supported = [&](VkFormat f) { return std::find(formats.begin(), formats.end(), f) != formats.end(); };
  if (!supported(spec.format))
    return finish(false, " the runtime offers no swapchain format " + std::to_string(spec.format));
  VkFormat depthFormat = VK_FORMAT_UNDEFINED;
  for (VkFormat f : {VK_FORMAT_D32_SFLOAT, VK_FORMAT_D16_UNORM})
    if (depthFormat == VK_FORMAT_UNDEFINED && supported(f)) depthFormat = f;
  if (spec.depth && (!depthExtension_ || depthFormat == VK_FORMAT_UNDEFINED))
    return finish(false, " no XR_KHR_composition_layer_depth or depth format");

  uint32_t w = 96, h = 80;  // small: lavapipe filters it quickly
  auto makeSwapchains = [&]() -> bool {
    for (auto& s : color) xrDestroySwapchain(s.handle);
    for (auto& s : depth) xrDestroySwapchain(s.handle);
    color.clear();
    depth.clear();
    const bool perEye = spec.kind == CaseKind::PerEye;
    const uint32_t cw = spec.kind == CaseKind::SideBySide || spec.kind == CaseKind::Invalid ? 2 * w : w;
    const uint32_t cl = spec.kind == CaseKind::Array ? 2 : 1;
    for (int i = 0; i < (perEye ? 2 : 1); ++i) {
      color.emplace_back();
      if (!createSwapchain(session, spec.format, cw, h, cl, false, &color.back())) return false;
      if (spec.depth) {
        depth.emplace_back();
        if (!createSwapchain(session, depthFormat, cw, h, cl, true, &depth.back())) return false;
      }
    }
    return true;
  };
  if (!makeSwapchains()) return finish(false, " xrCreateSwapchain failed");
  if (spec.multi && !createSwapchain(session, spec.format, 64, 64, 1, false, &quad))
    return finish(false, " quad swapchain");
  if (spec.kind == CaseKind::Invalid) {
    // A few valid frames first, so that the layer is set up and filtering.
    for (int f = 0; f < 4; ++f) {
      auto fs = xrStruct<XrFrameState>(XR_TYPE_FRAME_STATE);
      xrWaitFrame(session, nullptr, &fs);
      xrBeginFrame(session, nullptr);
      auto ei = xrStruct<XrFrameEndInfo>(XR_TYPE_FRAME_END_INFO);
      ei.displayTime = fs.predictedDisplayTime;
      ei.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
      xrEndFrame(session, &ei);
    }
    const std::string results = invalidCalls(session, space, color[0]);
    return finish(results.find("render failed") == std::string::npos, results);
  }

  int submitted = 0;
  for (int f = 0; f < frames; ++f) {
    if (spec.resize && f == frames / 2) {
      w = 72;
      h = 64;
      if (!makeSwapchains()) return finish(false, " resize: xrCreateSwapchain failed");
    }
    auto fs = xrStruct<XrFrameState>(XR_TYPE_FRAME_STATE);
    if (XR_FAILED(r = xrWaitFrame(session, nullptr, &fs)))
      return finish(false, " xrWaitFrame " + resultName(instance_, r));
    if (XR_FAILED(r = xrBeginFrame(session, nullptr)))
      return finish(false, " xrBeginFrame " + resultName(instance_, r));
    auto vli = xrStruct<XrViewLocateInfo>(XR_TYPE_VIEW_LOCATE_INFO);
    vli.viewConfigurationType = XR_VIEW_CONFIGURATION_TYPE_PRIMARY_STEREO;
    vli.displayTime = fs.predictedDisplayTime;
    vli.space = space;
    auto vs = xrStruct<XrViewState>(XR_TYPE_VIEW_STATE);
    std::array<XrView, 2> xv{xrStruct<XrView>(XR_TYPE_VIEW), xrStruct<XrView>(XR_TYPE_VIEW)};
    uint32_t vc = 0;
    xrLocateViews(session, &vli, &vs, 2, &vc, xv.data());
    for (auto& s : color)
      if (!render(s, s.width, s.height, s.layers, f, spec.translucent))
        return finish(false, " render failed");
    for (auto& s : depth)
      if (!render(s, s.width, s.height, s.layers, f, false)) return finish(false, " depth render failed");
    if (quad.handle && !render(quad, 64, 64, 1, f, false)) return finish(false, " quad render failed");
    std::array<XrCompositionLayerProjectionView, 2> views{};
    std::array<XrCompositionLayerDepthInfoKHR, 2> depthInfo{};
    for (uint32_t v = 0; v < 2; ++v) {
      views[v] = xrStruct<XrCompositionLayerProjectionView>(XR_TYPE_COMPOSITION_LAYER_PROJECTION_VIEW);
      views[v].pose = xv[v].pose;
      views[v].fov = xv[v].fov;
      const Swapchain& s = color[spec.kind == CaseKind::PerEye ? v : 0];
      views[v].subImage.swapchain = s.handle;
      views[v].subImage.imageRect = {{spec.kind == CaseKind::SideBySide ? int32_t(v * w) : 0, 0},
                                     {int32_t(w), int32_t(h)}};
      views[v].subImage.imageArrayIndex = spec.kind == CaseKind::Array ? v : 0;
      if (spec.depth) {
        depthInfo[v] = xrStruct<XrCompositionLayerDepthInfoKHR>(XR_TYPE_COMPOSITION_LAYER_DEPTH_INFO_KHR);
        depthInfo[v].subImage = views[v].subImage;
        depthInfo[v].subImage.swapchain = depth[spec.kind == CaseKind::PerEye ? v : 0].handle;
        depthInfo[v].minDepth = 0.0f;
        depthInfo[v].maxDepth = 1.0f;
        depthInfo[v].nearZ = 0.1f;
        depthInfo[v].farZ = 100.0f;
        views[v].next = &depthInfo[v];
      }
    }
    auto proj = xrStruct<XrCompositionLayerProjection>(XR_TYPE_COMPOSITION_LAYER_PROJECTION);
    proj.layerFlags = spec.flags;
    proj.space = space;
    proj.viewCount = 2;
    proj.views = views.data();
    auto proj2 = proj;  // a second projection layer (over the first, blended)
    proj2.layerFlags = XR_COMPOSITION_LAYER_BLEND_TEXTURE_SOURCE_ALPHA_BIT;
    auto q = xrStruct<XrCompositionLayerQuad>(XR_TYPE_COMPOSITION_LAYER_QUAD);
    q.space = space;
    q.eyeVisibility = XR_EYE_VISIBILITY_BOTH;
    q.subImage.swapchain = quad.handle;
    q.subImage.imageRect = {{0, 0}, {64, 64}};
    q.pose.orientation.w = 1.0f;
    q.pose.position.z = -1.0f;
    q.size = {0.3f, 0.3f};
    std::vector<const XrCompositionLayerBaseHeader*> layers{
        reinterpret_cast<XrCompositionLayerBaseHeader*>(&proj)};
    if (spec.multi) {
      layers.push_back(reinterpret_cast<XrCompositionLayerBaseHeader*>(&proj2));
      layers.push_back(reinterpret_cast<XrCompositionLayerBaseHeader*>(&q));
    }
    auto ei = xrStruct<XrFrameEndInfo>(XR_TYPE_FRAME_END_INFO);
    ei.displayTime = fs.predictedDisplayTime;
    ei.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
    ei.layerCount = static_cast<uint32_t>(layers.size());
    ei.layers = layers.data();
    if (XR_FAILED(r = xrEndFrame(session, &ei)))
      return finish(false, " xrEndFrame " + resultName(instance_, r));
    ++submitted;
  }
  return finish(true, " frames=" + std::to_string(submitted));
}

}  // namespace probe
