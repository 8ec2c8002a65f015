#include "probe_util.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <thread>

namespace probe {

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
  if (name == "loading") s.loading = true;
  if (name == "dynres") s.dynamicResolution = true;
  if (name == "invalid") {  // a side-by-side swapchain, then the invalid calls
    s.kind = CaseKind::Invalid;
    s.format = VK_FORMAT_R8G8B8A8_UNORM;
  }
  return s;
}

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
// Ends the frame with no layers, as an app does before it renders or while it shows nothing of its own.
XrResult endEmptyFrame(XrSession session, XrTime displayTime) {
  auto ei = xrStruct<XrFrameEndInfo>(XR_TYPE_FRAME_END_INFO);
  ei.displayTime = displayTime;
  ei.environmentBlendMode = XR_ENVIRONMENT_BLEND_MODE_OPAQUE;
  return xrEndFrame(session, &ei);
}

uint32_t pickFamily(VkPhysicalDevice pd) {
  uint32_t n = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(pd, &n, nullptr);
  std::vector<VkQueueFamilyProperties> f(n);
  vkGetPhysicalDeviceQueueFamilyProperties(pd, &n, f.data());
  for (uint32_t i = 0; i < n; ++i)
    if ((f[i].queueFlags & VK_QUEUE_GRAPHICS_BIT) && (f[i].queueFlags & VK_QUEUE_COMPUTE_BIT)) return i;
  return 0;
}

// The probe's VkInstanceCreateInfo at `apiVersion` (both Vulkan paths). Not copyable: the
// create info points at the application info.
struct InstanceCreateInfo {
  explicit InstanceCreateInfo(uint32_t apiVersion) {
    app.pApplicationName = "steadyxr-probe";
    app.apiVersion = apiVersion;
    info.pApplicationInfo = &app;
  }
  InstanceCreateInfo(const InstanceCreateInfo&) = delete;
  InstanceCreateInfo& operator=(const InstanceCreateInfo&) = delete;
  VkApplicationInfo app = vkStruct<VkApplicationInfo>(VK_STRUCTURE_TYPE_APPLICATION_INFO);
  VkInstanceCreateInfo info = vkStruct<VkInstanceCreateInfo>(VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO);
};

// The probe's VkDeviceCreateInfo (both Vulkan paths): one queue of `family`. Not copyable: the
// create info points at the queue info, which points at the priority.
struct DeviceCreateInfo {
  explicit DeviceCreateInfo(uint32_t family) {
    queue.queueFamilyIndex = family;
    queue.queueCount = 1;
    queue.pQueuePriorities = &priority;
    info.queueCreateInfoCount = 1;
    info.pQueueCreateInfos = &queue;
  }
  DeviceCreateInfo(const DeviceCreateInfo&) = delete;
  DeviceCreateInfo& operator=(const DeviceCreateInfo&) = delete;
  float priority = 1.0f;
  VkDeviceQueueCreateInfo queue =
      vkStruct<VkDeviceQueueCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO);
  VkDeviceCreateInfo info = vkStruct<VkDeviceCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO);
};
}  // namespace

bool Xr::initVulkanV2() {
  auto req = xrStruct<XrGraphicsRequirementsVulkan2KHR>(XR_TYPE_GRAPHICS_REQUIREMENTS_VULKAN2_KHR);
  xrFn<PFN_xrGetVulkanGraphicsRequirements2KHR>(instance_, "xrGetVulkanGraphicsRequirements2KHR")(
      instance_, system_, &req);
  instanceApiVersion = VK_API_VERSION_1_1;
  const InstanceCreateInfo ici(instanceApiVersion);
  auto xci = xrStruct<XrVulkanInstanceCreateInfoKHR>(XR_TYPE_VULKAN_INSTANCE_CREATE_INFO_KHR);
  xci.systemId = system_;
  xci.pfnGetInstanceProcAddr = vkGetInstanceProcAddr;
  xci.vulkanCreateInfo = &ici.info;
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
  const DeviceCreateInfo dci(family_);
  auto xdci = xrStruct<XrVulkanDeviceCreateInfoKHR>(XR_TYPE_VULKAN_DEVICE_CREATE_INFO_KHR);
  xdci.systemId = system_;
  xdci.pfnGetInstanceProcAddr = vkGetInstanceProcAddr;
  xdci.vulkanPhysicalDevice = physical_;
  xdci.vulkanCreateInfo = &dci.info;
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
  instanceApiVersion = VK_API_VERSION_1_3;
  InstanceCreateInfo ici(instanceApiVersion);
  ici.info.enabledExtensionCount = static_cast<uint32_t>(use.size());
  ici.info.ppEnabledExtensionNames = use.data();
  if (vkCreateInstance(&ici.info, nullptr, &vkInstance_) != VK_SUCCESS)
    return error = "vkCreateInstance", false;
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
  DeviceCreateInfo dci(family_);
  dci.info.enabledExtensionCount = static_cast<uint32_t>(devUse.size());
  dci.info.ppEnabledExtensionNames = devUse.data();
  if (vkCreateDevice(physical_, &dci.info, nullptr, &device_) != VK_SUCCESS)
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

CaseResult Xr::runCase(const CaseSpec& spec, int frames, const std::function<bool()>& layerFiltering) {
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
        endEmptyFrame(session, fs.predictedDisplayTime);
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
      endEmptyFrame(session, fs.predictedDisplayTime);
    }
    const std::string results = invalidCalls(session, space, color[0]);
    return finish(results.find("render failed") == std::string::npos, results);
  }

  int submitted = 0;
  int sizeChangesFrom = -1;  // dynamic resolution: the first frame of the changing sizes
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
    if (spec.loading && f >= loadingStart(frames) && f < loadingStart(frames) + kLoadingFrames) {
      if (XR_FAILED(r = endEmptyFrame(session, fs.predictedDisplayTime)))  // a loading screen
        return finish(false, " xrEndFrame (no layers) " + resultName(instance_, r));
      continue;
    }
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
    // Dynamic resolution: the app renders into less of the same image (the probe draws the whole image;
    // the rect picks a part of it). 0.8 of it until the layer filters, then a new size every frame: the
    // filter's first size, one larger (its images reallocated), smaller ones (kept). A rect smaller than
    // its image also moves inside it every frame (the history is in the rect's own pixels: kept).
    static constexpr float kRenderScale[] = {1.0f, 0.9f, 0.8f, 0.9f};
    if (spec.dynamicResolution && sizeChangesFrom < 0 && (!layerFiltering || layerFiltering()))
      sizeChangesFrom = f;
    const float scale = !spec.dynamicResolution ? 1.0f
                        : sizeChangesFrom < 0   ? 0.8f
                                                : kRenderScale[(f - sizeChangesFrom) % 4];
    const int32_t rw = int32_t(std::lround(float(w) * scale)), rh = int32_t(std::lround(float(h) * scale));
    const XrOffset2Di moved = !spec.dynamicResolution ? XrOffset2Di{0, 0}
                                                      : XrOffset2Di{(5 * f) % (int32_t(w) - rw + 1),
                                                                    (3 * f) % (int32_t(h) - rh + 1)};
    std::array<XrCompositionLayerProjectionView, 2> views{};
    std::array<XrCompositionLayerDepthInfoKHR, 2> depthInfo{};
    for (uint32_t v = 0; v < 2; ++v) {
      views[v] = xrStruct<XrCompositionLayerProjectionView>(XR_TYPE_COMPOSITION_LAYER_PROJECTION_VIEW);
      views[v].pose = xv[v].pose;
      views[v].fov = xv[v].fov;
      const Swapchain& s = color[spec.kind == CaseKind::PerEye ? v : 0];
      views[v].subImage.swapchain = s.handle;
      views[v].subImage.imageRect = {
          {(spec.kind == CaseKind::SideBySide ? int32_t(v * w) : 0) + moved.x, moved.y}, {rw, rh}};
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
