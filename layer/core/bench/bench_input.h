// The benchmark's eye images: a picture fixed in the world and rendered for each frame's pose, so that
// the passes' data-dependent work (the clip's rejections, the noise estimate's histograms, the gain test,
// a GPU's divergent branches and its lossless colour compression) is what an app's frames cause. A flat
// clear (--input flat, the bench before round 28) takes none of it: its 3x3s are flat, its probe finds
// no detail and a GPU compresses it to almost nothing.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <functional>
#include <glm/gtc/quaternion.hpp>
#include <glm/vec4.hpp>
#include <string>
#include <vector>

#include "steadyxr/core/frame.h"
#include "steadyxr/core/vulkan_context.h"

namespace steadyxr::bench {

// A zone plate on a plane at infinity straight ahead of the world's -Z axis, point-sampled at each
// pixel centre of a view with this fov and orientation (row 0 at the top, as Vulkan's NDC has it). Its
// rings' frequency grows with the distance from the axis and reaches the pixel grid's Nyquist limit
// halfway out to the view's edge: fine detail that resolves inside, and aliasing that shimmers under
// head tremor outside, as an app's render without antialiasing does. The channels' rings differ a
// little in frequency, so the picture has chroma. Linear RGB in [0, 1], alpha 1, row by row.
std::vector<glm::vec4> renderZonePlate(VkExtent2D size, const core::Fov& fov, const glm::quat& orientation);

// The world direction through the centre of pixel (x, y) (the renderer's own mapping, for its test).
glm::vec3 pixelDirection(VkExtent2D size, const core::Fov& fov, const glm::quat& orientation, float x,
                         float y);

// Records `record` on a one-time command buffer between the image's transitions from UNDEFINED to
// TRANSFER_DST_OPTIMAL and on to SHADER_READ_ONLY_OPTIMAL (one level and layer), submits it and waits.
bool fillImage(core::VulkanContext& ctx, VkImage image, const std::function<void(VkCommandBuffer)>& record,
               std::string* error, VkImageAspectFlags aspect = VK_IMAGE_ASPECT_COLOR_BIT);
// --input flat: one colour everywhere, as vkCmdClearColorImage takes it.
bool clearImage(core::VulkanContext& ctx, VkImage image, const glm::vec4& colour, std::string* error);
// --depth: one depth value everywhere (a D32 image), as vkCmdClearDepthStencilImage takes it.
bool clearDepthImage(core::VulkanContext& ctx, VkImage image, float depth, std::string* error);

// Copies `pixels` (linear RGB, as renderZonePlate gives them) into `image` (one level and layer, in
// `format`: sRGB and UNORM RGBA8 or RGBA16F) through a staging buffer and leaves it in
// SHADER_READ_ONLY_OPTIMAL. UNORM gets the values as codes, as an app that renders in encoded values.
bool uploadImage(core::VulkanContext& ctx, VkImage image, VkFormat format, VkExtent2D size,
                 const std::vector<glm::vec4>& pixels, std::string* error);

}  // namespace steadyxr::bench
