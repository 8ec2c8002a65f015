// Entry points: loader negotiation, instance creation, xrGetInstanceProcAddr and the hooks.
// Every hook finds its state in the registry, then forwards to the next layer; unknown handles
// are forwarded untouched when possible.
#include "loader_interfaces.h"
#include "session.h"

#include <algorithm>
#include <cstring>
#include <exception>
#include <map>
#include <memory>
#include <mutex>

#if defined(__GNUC__)
#define STEADYXR_EXPORT extern "C" __attribute__((visibility("default")))
#else
#define STEADYXR_EXPORT extern "C"
#endif

namespace steadyxr::layer {
namespace {

// The layer's only global mutable state: handle -> state maps behind one mutex.
class Registry {
 public:
  void addInstance(std::shared_ptr<InstanceState> s) {
    const XrInstance h = s->handle;
    std::lock_guard lock(m_);
    instances_[h] = std::move(s);
  }
  std::shared_ptr<InstanceState> instance(XrInstance h) {
    std::lock_guard lock(m_);
    auto it = instances_.find(h);
    return it == instances_.end() ? nullptr : it->second;
  }
  std::vector<std::shared_ptr<Session>> removeInstance(XrInstance h) {
    std::lock_guard lock(m_);
    std::vector<std::shared_ptr<Session>> orphans;
    auto inst = instances_.find(h);
    if (inst == instances_.end()) return orphans;
    for (auto it = sessions_.begin(); it != sessions_.end();) {
      if (it->second.instance == inst->second.get()) {
        orphans.push_back(it->second.session);
        it = sessions_.erase(it);
      } else {
        ++it;
      }
    }
    for (auto it = swapchains_.begin(); it != swapchains_.end();) {
      bool orphan = false;
      for (auto& s : orphans) orphan = orphan || it->second.get() == s.get();
      it = orphan ? swapchains_.erase(it) : std::next(it);
    }
    instances_.erase(inst);
    return orphans;
  }
  void addSession(const InstanceState* inst, std::shared_ptr<Session> s) {
    const XrSession h = s->handle();  // read before the move below
    std::lock_guard lock(m_);
    sessions_[h] = {inst, std::move(s)};
  }
  std::shared_ptr<Session> session(XrSession h) {
    std::lock_guard lock(m_);
    auto it = sessions_.find(h);
    return it == sessions_.end() ? nullptr : it->second.session;
  }
  std::shared_ptr<Session> removeSession(XrSession h) {
    std::lock_guard lock(m_);
    auto it = sessions_.find(h);
    if (it == sessions_.end()) return nullptr;
    std::shared_ptr<Session> s = it->second.session;
    sessions_.erase(it);
    for (auto sc = swapchains_.begin(); sc != swapchains_.end();) {
      sc = sc->second == s ? swapchains_.erase(sc) : std::next(sc);
    }
    return s;
  }
  void addSwapchain(XrSwapchain h, std::shared_ptr<Session> s) {
    std::lock_guard lock(m_);
    swapchains_[h] = std::move(s);
  }
  std::shared_ptr<Session> swapchainSession(XrSwapchain h) {
    std::lock_guard lock(m_);
    auto it = swapchains_.find(h);
    return it == swapchains_.end() ? nullptr : it->second;
  }
  void removeSwapchain(XrSwapchain h) {
    std::lock_guard lock(m_);
    swapchains_.erase(h);
  }

 private:
  struct SessionEntry {
    const InstanceState* instance;
    std::shared_ptr<Session> session;
  };
  std::mutex m_;
  std::map<XrInstance, std::shared_ptr<InstanceState>> instances_;
  std::map<XrSession, SessionEntry> sessions_;
  std::map<XrSwapchain, std::shared_ptr<Session>> swapchains_;
};

// Deliberately never destroyed: at process exit the runtime may already be unloaded, and
// tearing sessions down then would call into it.
Registry& registry() {
  static Registry* const r = new Registry;
  return *r;
}

// Exceptions must never cross into the app: turn them into a runtime failure.
template <typename F>
XrResult guarded(F&& f) {
  try {
    return f();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "[steadyxr] error: unexpected exception: %s\n", e.what());
  } catch (...) {
    std::fprintf(stderr, "[steadyxr] error: unexpected exception\n");
  }
  return XR_ERROR_RUNTIME_FAILURE;
}

XRAPI_ATTR XrResult XRAPI_CALL hookGetInstanceProcAddr(XrInstance instance, const char* name,
                                                       PFN_xrVoidFunction* function);

XRAPI_ATTR XrResult XRAPI_CALL hookDestroyInstance(XrInstance instance) {
  return guarded([&] {
    std::shared_ptr<InstanceState> inst = registry().instance(instance);
    if (!inst) return XR_ERROR_HANDLE_INVALID;
    for (auto& s : registry().removeInstance(instance)) s->shutdown();
    return inst->next.destroyInstance(instance);
  });
}

std::optional<XrGraphicsBindingVulkanKHR> findVulkanBinding(const void* next) {
  // XrGraphicsBindingVulkan2KHR (XR_KHR_vulkan_enable2) is the same struct and type value.
  // The walk is bounded: a cyclic chain ends it.
  uint32_t walked = 0;
  for (auto* h = static_cast<const XrBaseInStructure*>(next); h != nullptr && walked < kMaxNextChain;
       h = h->next, ++walked) {
    if (h->type == XR_TYPE_GRAPHICS_BINDING_VULKAN_KHR)
      return *reinterpret_cast<const XrGraphicsBindingVulkanKHR*>(h);
  }
  return std::nullopt;
}

XRAPI_ATTR XrResult XRAPI_CALL hookCreateSession(XrInstance instance, const XrSessionCreateInfo* info,
                                                 XrSession* session) {
  return guarded([&] {
    std::shared_ptr<InstanceState> inst = registry().instance(instance);
    if (!inst) return XR_ERROR_HANDLE_INVALID;
    const XrResult r = inst->next.createSession(instance, info, session);
    if (XR_FAILED(r) || info == nullptr || session == nullptr) return r;
    // The session exists for the app from here on: it must be registered whatever happens, or
    // every later call on it would fail with XR_ERROR_HANDLE_INVALID. Session's constructor
    // catches its own set-up failures; this catches the allocation itself failing.
    try {
      registry().addSession(inst.get(), std::make_shared<Session>(inst, *session, info->systemId,
                                                                  findVulkanBinding(info->next)));
    } catch (const std::exception& e) {
      inst->log->log(LogLevel::Error,
                     std::string("session set-up failed (") + e.what() + "): passing through");
      registry().addSession(inst.get(),
                            std::make_shared<Session>(inst, *session, info->systemId, std::nullopt));
    }
    return r;
  });
}

XRAPI_ATTR XrResult XRAPI_CALL hookDestroySession(XrSession session) {
  return guarded([&] {
    std::shared_ptr<Session> s = registry().removeSession(session);
    if (!s) return XR_ERROR_HANDLE_INVALID;
    s->shutdown();  // before the runtime destroys the session's swapchains
    return s->next().destroySession(session);
  });
}

XRAPI_ATTR XrResult XRAPI_CALL hookCreateSwapchain(XrSession session, const XrSwapchainCreateInfo* info,
                                                   XrSwapchain* swapchain) {
  return guarded([&] {
    std::shared_ptr<Session> s = registry().session(session);
    if (!s) return XR_ERROR_HANDLE_INVALID;
    const XrResult r = s->createSwapchain(info, swapchain);
    if (XR_SUCCEEDED(r)) registry().addSwapchain(*swapchain, s);
    return r;
  });
}

XRAPI_ATTR XrResult XRAPI_CALL hookDestroySwapchain(XrSwapchain swapchain) {
  return guarded([&] {
    std::shared_ptr<Session> s = registry().swapchainSession(swapchain);
    if (!s) return XR_ERROR_HANDLE_INVALID;
    registry().removeSwapchain(swapchain);
    return s->destroySwapchain(swapchain);
  });
}

XRAPI_ATTR XrResult XRAPI_CALL hookEnumerateSwapchainImages(XrSwapchain swapchain, uint32_t capacity,
                                                            uint32_t* count,
                                                            XrSwapchainImageBaseHeader* images) {
  return guarded([&] {
    std::shared_ptr<Session> s = registry().swapchainSession(swapchain);
    if (!s) return XR_ERROR_HANDLE_INVALID;
    return s->enumerateImages(swapchain, capacity, count, images);
  });
}

XRAPI_ATTR XrResult XRAPI_CALL hookAcquireSwapchainImage(XrSwapchain swapchain,
                                                         const XrSwapchainImageAcquireInfo* info,
                                                         uint32_t* index) {
  return guarded([&] {
    std::shared_ptr<Session> s = registry().swapchainSession(swapchain);
    if (!s) return XR_ERROR_HANDLE_INVALID;
    return s->acquire(swapchain, info, index);
  });
}

XRAPI_ATTR XrResult XRAPI_CALL hookWaitSwapchainImage(XrSwapchain swapchain,
                                                      const XrSwapchainImageWaitInfo* info) {
  return guarded([&] {
    std::shared_ptr<Session> s = registry().swapchainSession(swapchain);
    if (!s) return XR_ERROR_HANDLE_INVALID;
    return s->next().waitSwapchainImage(swapchain, info);
  });
}

XRAPI_ATTR XrResult XRAPI_CALL hookReleaseSwapchainImage(XrSwapchain swapchain,
                                                         const XrSwapchainImageReleaseInfo* info) {
  return guarded([&] {
    std::shared_ptr<Session> s = registry().swapchainSession(swapchain);
    if (!s) return XR_ERROR_HANDLE_INVALID;
    return s->release(swapchain, info);
  });
}

XRAPI_ATTR XrResult XRAPI_CALL hookLocateViews(XrSession session, const XrViewLocateInfo* info,
                                               XrViewState* state, uint32_t capacity, uint32_t* count,
                                               XrView* views) {
  return guarded([&] {
    std::shared_ptr<Session> s = registry().session(session);
    if (!s) return XR_ERROR_HANDLE_INVALID;
    return s->locateViews(info, state, capacity, count, views);
  });
}

XRAPI_ATTR XrResult XRAPI_CALL hookEndFrame(XrSession session, const XrFrameEndInfo* info) {
  return guarded([&] {
    std::shared_ptr<Session> s = registry().session(session);
    if (!s) return XR_ERROR_HANDLE_INVALID;
    return s->endFrame(info);
  });
}

XRAPI_ATTR XrResult XRAPI_CALL hookCreateVulkanInstanceKHR(XrInstance instance,
                                                           const XrVulkanInstanceCreateInfoKHR* info,
                                                           VkInstance* vkInstance, VkResult* vkResult) {
  return guarded([&] {
    std::shared_ptr<InstanceState> inst = registry().instance(instance);
    if (!inst || inst->next.createVulkanInstanceKHR == nullptr) return XR_ERROR_HANDLE_INVALID;
    // The filter core needs Vulkan 1.1: ask for it when the app asks for less (a later version
    // changes nothing for an app written against 1.0). Fall back to the app's request.
    // Invalid input (no create info) goes to the runtime untouched: it answers it.
    if (info == nullptr || info->vulkanCreateInfo == nullptr)
      return inst->next.createVulkanInstanceKHR(instance, info, vkInstance, vkResult);
    const VkApplicationInfo* appInfo = info->vulkanCreateInfo->pApplicationInfo;
    const uint32_t asked =
        (appInfo == nullptr || appInfo->apiVersion == 0) ? VK_API_VERSION_1_0 : appInfo->apiVersion;
    XrResult r = XR_ERROR_RUNTIME_FAILURE;
    if (!inst->config.environmentDisabled && asked < VK_API_VERSION_1_1) {
      VkApplicationInfo ai =
          appInfo ? *appInfo : makeVk<VkApplicationInfo>(VK_STRUCTURE_TYPE_APPLICATION_INFO);
      ai.apiVersion = VK_API_VERSION_1_1;
      VkInstanceCreateInfo ci = *info->vulkanCreateInfo;
      ci.pApplicationInfo = &ai;
      XrVulkanInstanceCreateInfoKHR xi = *info;
      xi.vulkanCreateInfo = &ci;
      r = inst->next.createVulkanInstanceKHR(instance, &xi, vkInstance, vkResult);
      if (XR_SUCCEEDED(r) && vkResult && *vkResult == VK_SUCCESS) {
        inst->vulkanApiVersion = VK_API_VERSION_1_1;
        return r;
      }
      inst->log->log(LogLevel::Warn,
                     "could not create the Vulkan instance as 1.1; filtering may be unavailable");
    }
    r = inst->next.createVulkanInstanceKHR(instance, info, vkInstance, vkResult);
    if (XR_SUCCEEDED(r)) inst->vulkanApiVersion = asked;
    return r;
  });
}

struct Hook {
  const char* name;
  PFN_xrVoidFunction function;
};
#define STEADYXR_HOOK(name, fn) \
  { name, reinterpret_cast<PFN_xrVoidFunction>(fn) }
const Hook kHooks[] = {
    STEADYXR_HOOK("xrGetInstanceProcAddr", hookGetInstanceProcAddr),
    STEADYXR_HOOK("xrDestroyInstance", hookDestroyInstance),
    STEADYXR_HOOK("xrCreateSession", hookCreateSession),
    STEADYXR_HOOK("xrDestroySession", hookDestroySession),
    STEADYXR_HOOK("xrCreateSwapchain", hookCreateSwapchain),
    STEADYXR_HOOK("xrDestroySwapchain", hookDestroySwapchain),
    STEADYXR_HOOK("xrEnumerateSwapchainImages", hookEnumerateSwapchainImages),
    STEADYXR_HOOK("xrAcquireSwapchainImage", hookAcquireSwapchainImage),
    STEADYXR_HOOK("xrWaitSwapchainImage", hookWaitSwapchainImage),
    STEADYXR_HOOK("xrReleaseSwapchainImage", hookReleaseSwapchainImage),
    STEADYXR_HOOK("xrLocateViews", hookLocateViews),
    STEADYXR_HOOK("xrEndFrame", hookEndFrame),
    STEADYXR_HOOK("xrCreateVulkanInstanceKHR", hookCreateVulkanInstanceKHR),
};
#undef STEADYXR_HOOK

XRAPI_ATTR XrResult XRAPI_CALL hookGetInstanceProcAddr(XrInstance instance, const char* name,
                                                       PFN_xrVoidFunction* function) {
  return guarded([&] {
    if (name == nullptr || function == nullptr) return XR_ERROR_VALIDATION_FAILURE;
    std::shared_ptr<InstanceState> inst = registry().instance(instance);
    if (!inst) {
      *function = nullptr;
      return XR_ERROR_HANDLE_INVALID;
    }
    const XrResult r = inst->next.getInstanceProcAddr(instance, name, function);
    // A disabled layer hooks nothing; functions the next layer lacks are not hooked either.
    if (XR_FAILED(r) || *function == nullptr || inst->config.environmentDisabled) return r;
    for (const Hook& h : kHooks) {
      if (std::strcmp(h.name, name) == 0) {
        *function = h.function;
        break;
      }
    }
    return r;
  });
}

// Config file watching and the status file: a hooked instance only, and never fatal.
void startLiveParts(InstanceState& state) {
  state.live =
      std::make_unique<LiveConfig>(state.config, state.applicationName, processEnvironment(), *state.log);
  std::string error;
  const char* runtimeDir = std::getenv("XDG_RUNTIME_DIR");
  state.status = StatusFile::create(runtimeDir ? runtimeDir : "", &error);
  if (!state.status) state.log->log(LogLevel::Info, "status: no status file (" + error + ")");
}

XRAPI_ATTR XrResult XRAPI_CALL createApiLayerInstance(const XrInstanceCreateInfo* info,
                                                      const XrApiLayerCreateInfo* layerInfo,
                                                      XrInstance* instance) {
  return guarded([&] {
    if (info == nullptr || layerInfo == nullptr || instance == nullptr || layerInfo->nextInfo == nullptr ||
        layerInfo->structType != XR_LOADER_INTERFACE_STRUCT_API_LAYER_CREATE_INFO ||
        layerInfo->nextInfo->structType != XR_LOADER_INTERFACE_STRUCT_API_LAYER_NEXT_INFO ||
        std::strcmp(layerInfo->nextInfo->layerName, kLayerName) != 0 ||
        layerInfo->nextInfo->nextGetInstanceProcAddr == nullptr ||
        layerInfo->nextInfo->nextCreateApiLayerInstance == nullptr) {
      return XR_ERROR_INITIALIZATION_FAILED;
    }
    // The next layer sees the chain advanced by one.
    XrApiLayerCreateInfo nextLayerInfo = *layerInfo;
    nextLayerInfo.nextInfo = layerInfo->nextInfo->next;
    const PFN_xrGetInstanceProcAddr nextGipa = layerInfo->nextInfo->nextGetInstanceProcAddr;
    std::vector<std::string> messages;
    // applicationName is a fixed array the app should NUL-terminate; read no further than it.
    const std::string appName(info->applicationInfo.applicationName,
                              strnlen(info->applicationInfo.applicationName, XR_MAX_APPLICATION_NAME_SIZE));
    const Config config = loadConfig(appName, processEnvironment(), &messages);

    // pose_source = imu needs XrTime -> CLOCK_MONOTONIC (the IMU's clock), and
    // XR_KHR_convert_timespec_time is the only way to get it: the layer enables it for its own
    // use, only then. Enabling an instance extension adds functions and changes nothing the
    // app's calls do; a runtime without it gets the instance as asked (head speed then comes
    // from the runtime's poses). Nothing is added for an invalid extension list.
    XrResult r = XR_ERROR_EXTENSION_NOT_PRESENT;
    bool timespecAdded = false;
    const bool extensionsReadable =
        info->enabledExtensionCount == 0 || info->enabledExtensionNames != nullptr;
    if (!config.environmentDisabled && config.poseSource == PoseSourceKind::Imu && extensionsReadable) {
      std::vector<const char*> exts(info->enabledExtensionNames,
                                    info->enabledExtensionNames + info->enabledExtensionCount);
      const bool present = std::any_of(exts.begin(), exts.end(), [](const char* e) {
        return e != nullptr && std::strcmp(e, XR_KHR_CONVERT_TIMESPEC_TIME_EXTENSION_NAME) == 0;
      });
      if (!present) {
        exts.push_back(XR_KHR_CONVERT_TIMESPEC_TIME_EXTENSION_NAME);
        XrInstanceCreateInfo withTimespec = *info;
        withTimespec.enabledExtensionCount = static_cast<uint32_t>(exts.size());
        withTimespec.enabledExtensionNames = exts.data();
        r = layerInfo->nextInfo->nextCreateApiLayerInstance(&withTimespec, &nextLayerInfo, instance);
        timespecAdded = XR_SUCCEEDED(r);
      }
    }
    if (!timespecAdded) r = layerInfo->nextInfo->nextCreateApiLayerInstance(info, &nextLayerInfo, instance);
    if (XR_FAILED(r)) return r;

    auto state = std::make_shared<InstanceState>();
    state->handle = *instance;
    state->applicationName = appName;
    state->config = config;
    state->log = std::make_unique<Logger>(state->config.logLevel, state->config.logFile);
    for (const std::string& m : messages) state->log->log(LogLevel::Warn, m);
    if (!loadDispatch(*instance, nextGipa, &state->next)) {
      state->log->log(LogLevel::Error, "the next layer lacks core functions: the layer stays out of the way");
      state->config.enabled = false;
      state->config.environmentDisabled = true;
      state->next.getInstanceProcAddr = nextGipa;
    }
    state->log->log(
        LogLevel::Info,
        std::string(kLayerName) + " loaded for '" + state->applicationName + "': " +
            (state->config.environmentDisabled ? std::string("disabled")
             : state->config.enabled
                 ? "enabled, method " + state->config.method +
                       (state->config.profile == "default" ? "" : ", profile " + state->config.profile)
                 : "loaded with enabled = 0 (frames pass through until it is 1)") +
            (state->config.configFile.empty() ? "" : ", config " + state->config.configFile));
    if (!state->config.environmentDisabled) startLiveParts(*state);
    registry().addInstance(std::move(state));
    return r;
  });
}

}  // namespace
}  // namespace steadyxr::layer

STEADYXR_EXPORT XRAPI_ATTR XrResult XRAPI_CALL xrNegotiateLoaderApiLayerInterface(
    const XrNegotiateLoaderInfo* loaderInfo, const char* layerName, XrNegotiateApiLayerRequest* request) {
  using namespace steadyxr::layer;
  if (loaderInfo == nullptr || request == nullptr || layerName == nullptr ||
      std::strcmp(layerName, kLayerName) != 0 ||
      loaderInfo->structType != XR_LOADER_INTERFACE_STRUCT_LOADER_INFO ||
      loaderInfo->structVersion != XR_LOADER_INFO_STRUCT_VERSION ||
      loaderInfo->structSize != sizeof(XrNegotiateLoaderInfo) ||
      request->structType != XR_LOADER_INTERFACE_STRUCT_API_LAYER_REQUEST ||
      request->structVersion != XR_API_LAYER_INFO_STRUCT_VERSION ||
      request->structSize != sizeof(XrNegotiateApiLayerRequest) ||
      loaderInfo->minInterfaceVersion > XR_CURRENT_LOADER_API_LAYER_VERSION ||
      loaderInfo->maxInterfaceVersion < XR_CURRENT_LOADER_API_LAYER_VERSION ||
      loaderInfo->minApiVersion > XR_CURRENT_API_VERSION) {
    return XR_ERROR_INITIALIZATION_FAILED;
  }
  request->layerInterfaceVersion = XR_CURRENT_LOADER_API_LAYER_VERSION;
  request->layerApiVersion = XR_CURRENT_API_VERSION;
  request->getInstanceProcAddr = hookGetInstanceProcAddr;
  request->createApiLayerInstance = createApiLayerInstance;
  return XR_SUCCESS;
}
