// Plain value types that describe one stereo frame handed to the filter core.
// Conventions follow OpenXR: right-handed, +X right, +Y up, -Z forward; a Pose is the
// eye's pose in a fixed reference space (view-to-world); a Fov is four angles in radians
// (angleLeft and angleDown are normally negative). Image row 0 is the top (angleUp side).
#pragma once

#include <vulkan/vulkan.h>

#include <array>
#include <cstdint>
#include <optional>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace steadyxr::core {

struct Fov {
  float angleLeft = -0.785398f;
  float angleRight = 0.785398f;
  float angleUp = 0.785398f;
  float angleDown = -0.785398f;
};

struct Pose {
  glm::quat orientation{1.0f, 0.0f, 0.0f, 0.0f};  // w, x, y, z
  glm::vec3 position{0.0f};                       // metres
};

// One 2D region of one array layer of a Vulkan image.
struct ImageRef {
  VkImage image = VK_NULL_HANDLE;
  VkFormat format = VK_FORMAT_UNDEFINED;
  VkExtent2D extent{};  // size of the whole image (mip 0)
  uint32_t arrayLayer = 0;
  uint32_t arrayLayerCount = 1;  // layers the image was created with
  VkRect2D rect{};               // the sub-image the view occupies (OpenXR imageRect)
  VkImageUsageFlags usage = 0;   // usage the image was created with
  bool mutableFormat = false;    // created with VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT
  // Layout the image is in when the filter's commands start; the filter leaves it in
  // finalLayout (defaults to the same layout).
  VkImageLayout layout = VK_IMAGE_LAYOUT_UNDEFINED;
  std::optional<VkImageLayout> finalLayout;
};

// Depth as OpenXR's XrCompositionLayerDepthInfoKHR describes it.
struct DepthRef {
  ImageRef image;
  float minDepth = 0.0f;
  float maxDepth = 1.0f;
  float nearZ = 0.1f;  // nearZ > farZ means reversed-Z; farZ may be +inf
  float farZ = 1000.0f;
};

struct ViewFrame {
  ImageRef color;
  std::optional<DepthRef> depth;
  Pose pose;
  Fov fov;
  // Sub-pixel jitter the colour (and depth) was rendered with: its grid is shifted by this many
  // pixels (x right, y down) from the grid `fov` defines, so the point at output pixel centre c
  // appears in the input at c - jitterPx. Output and history lie on `fov`'s (unjittered) grid.
  // Only the temporal methods un-jitter; others ignore it. Zero for apps that do not jitter.
  glm::vec2 jitterPx{0.0f};
};

struct StereoFrame {
  std::array<ViewFrame, 2> views;
  uint32_t viewCount = 2;           // 1 disables the stereo pass
  int64_t displayTimeNs = 0;        // predicted display time of this frame
  float headSpeedDegPerSec = 0.0f;  // h for seed 003 Eq. 4, computed on the CPU by the caller
  bool reset = false;               // drop all history before filtering this frame
};

struct StereoOutput {
  std::array<ImageRef, 2> views;  // same size as the inputs' rects; may alias one image (array/side-by-side)
};

// GPU time of each pass of the last completed frame, both eyes together, in milliseconds.
struct PassTimings {
  double temporalMs = 0.0;
  double probeMs = 0.0;  // of temporalMs: steady's probe of the frame (noise, gain, head-locked samples)
  double stereoMs = 0.0;
  double otherMs = 0.0;  // conversion / copy work
  double totalMs = 0.0;
  uint64_t frameIndex = 0;  // which submitted frame these belong to
};

// How the filter met an app's changes of render size (dynamic resolution), counted over the frames it
// filtered since it was made.
struct RenderSizeCounters {
  uint64_t framesResized = 0;       // a view's rect size differs from its size in the frame before
  uint64_t historyKeptResized = 0;  // a temporal method reprojected a history written at another size
  // The internal images made anew (a rect that outgrew them), each dropping the history.
  uint64_t imagesReallocated = 0;
};

// What steady's gain probe (Params::steadyGainCompensation) summed in a frame, both eyes together: its
// samples, and their mean luma (R/4 + G/2 + B/4, each sample clamped to [0, 1]) in this frame and in the
// history reprojected to it, and the mean magnitude of their difference (clamped to 0.5); round 31
// (Params::steadyUnexplainedFrameResets): the same luma's mean over the 4x4-pixel block around each sample
// (its centre the sample's lower right corner), the mean magnitude of its change since the history and of
// its step to the block a block to the right (samples i + j even) or below (odd; round 32: one neighbour a
// sample, half the taps, the same mean; each clamped to 0.5; 0 when off); round 33: each block's structure
// (the mean magnitude of the differences between its left and right halves and its top and bottom halves,
// from its four 2x2 quads) in this frame and in the history, where the history has one.
// The frame's gain, whether it explains the change (round 17) and whether the pose explains the frame
// (round 31) are decided from these on the GPU (temporal.comp).
struct GainProbeSums {
  uint32_t samples = 0;
  double currentMeanLuma = 0.0;
  double historyMeanLuma = 0.0;
  double meanChangeMagnitude = 0.0;
  double meanBlockChange = 0.0;
  double meanBlockStep = 0.0;
  double meanFrameStructure = 0.0;    // round 33: the block's halves' differences in this frame
  double meanHistoryStructure = 0.0;  // and in the history's block (not relit)
  uint64_t frameIndex = 0;            // which submitted frame these belong to
};

}  // namespace steadyxr::core
