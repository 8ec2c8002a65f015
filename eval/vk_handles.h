// Names for the owners of the Vulkan handles the harness creates: the core's one
// move-only owner (steadyxr/core/vk_handle.h), destroyed with their device.
#pragma once

#include "steadyxr/core/vk_handle.h"

namespace steadyxr::eval {

using UniqueImage = core::Unique<VkImage>;
using UniqueImageView = core::Unique<VkImageView>;
using UniqueBuffer = core::Unique<VkBuffer>;
using UniqueMemory = core::Unique<VkDeviceMemory>;
using UniqueSampler = core::Unique<VkSampler>;
using UniqueRenderPass = core::Unique<VkRenderPass>;
using UniqueFramebuffer = core::Unique<VkFramebuffer>;
using UniquePipeline = core::Unique<VkPipeline>;
using UniquePipelineLayout = core::Unique<VkPipelineLayout>;
using UniqueSetLayout = core::Unique<VkDescriptorSetLayout>;
using UniqueDescriptorPool = core::Unique<VkDescriptorPool>;
using UniqueShaderModule = core::Unique<VkShaderModule>;
using UniqueCommandPool = core::Unique<VkCommandPool>;
using UniqueFence = core::Unique<VkFence>;
using UniqueQueryPool = core::Unique<VkQueryPool>;

}  // namespace steadyxr::eval
