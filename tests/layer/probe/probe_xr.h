// The probe's OpenXR + Vulkan side: instance, device, and one session per case.
#pragma once

#include <vulkan/vulkan.h>
#define XR_USE_GRAPHICS_API_VULKAN
#include <openxr/openxr.h>
#include <openxr/openxr_platform.h>

#include <functional>
#include <string>
#include <vector>

namespace probe {

enum class Api { V1, V2 };
enum class CaseKind { PerEye, Array, SideBySide, Invalid };

struct CaseSpec {
  CaseKind kind = CaseKind::PerEye;
  VkFormat format = VK_FORMAT_R8G8B8A8_SRGB;
  XrCompositionLayerFlags flags = 0;
  bool depth = false;
  bool multi = false;              // a second projection layer and a quad after the first
  bool resize = false;             // new swapchains of another size half-way
  bool loading = false;            // frames without layers three quarters in (a loading screen)
  bool dynamicResolution = false;  // the rect's size changes every frame (see runCase)
  bool translucent = false;
  bool expectFiltered = true;
  bool dumpable = true;      // 8-bit: the layer dumps it
  std::string expectReason;  // when not filtered: the layer's pass-through reason
};
CaseSpec caseSpec(const std::string& name);
// The loading case's frames without layers: how many, and the first.
constexpr int kLoadingFrames = 3;
inline int loadingStart(int frames) {
  return frames * 3 / 4;
}

struct CaseResult {
  bool ok = false;
  std::string detail;
};

class Xr {
 public:
  ~Xr();
  bool init(Api api);
  // layerFiltering (optional): whether the layer has filtered a frame of this case yet (the
  // dynamic-resolution case starts changing its size then, so that the filter sees a first size,
  // a larger one and a smaller one, however many frames its pipelines take to compile).
  CaseResult runCase(const CaseSpec& spec, int frames, const std::function<bool()>& layerFiltering = {});

  std::string error;
  std::string deviceName;
  std::string enabledDeviceExtensions;
  uint32_t instanceApiVersion = 0;

 private:
  struct Swapchain {
    XrSwapchain handle = XR_NULL_HANDLE;
    std::vector<VkImage> images;
    VkFormat format = VK_FORMAT_UNDEFINED;
    uint32_t width = 0, height = 0, layers = 1;
    bool depth = false;
  };
  bool initVulkanV2();
  bool initVulkanV1();
  bool pollUntil(XrSessionState want, XrSession session, int timeoutMs);
  bool createSwapchain(XrSession s, VkFormat format, uint32_t w, uint32_t h, uint32_t layers, bool depth,
                       Swapchain* out);
  bool render(Swapchain& sc, uint32_t w, uint32_t h, uint32_t layers, int frame, bool translucent);
  std::string invalidCalls(XrSession session, XrSpace space, Swapchain& sc);

  Api api_ = Api::V2;
  XrInstance instance_ = XR_NULL_HANDLE;
  XrSystemId system_ = XR_NULL_SYSTEM_ID;
  VkInstance vkInstance_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  uint32_t family_ = 0;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  bool depthExtension_ = false;
  uint32_t maxLayers_ = 16;
};

}  // namespace probe
