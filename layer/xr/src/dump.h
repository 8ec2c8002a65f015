// Debug dump: reads back the first N frames' input and output eye images and writes them as
// PNG (stb_image_write). Synchronous on purpose: it is for inspection, never on by default.
#pragma once

#include "log.h"
#include "steadyxr/core/frame.h"
#include "steadyxr/core/vulkan_context.h"

#include <cstdint>
#include <string>

namespace steadyxr::layer {

class ImageDumper {
 public:
  ImageDumper(std::string dir, uint32_t maxFrames) : dir_(std::move(dir)), maxFrames_(maxFrames) {}
  bool wants() const { return frame_ < maxFrames_; }
  // Writes <dir>/frame<NNNN>_<view>_<tag>.png for each view; call after the filter's submit,
  // before the output images are released. Returns false (and logs) on failure.
  void dump(core::VulkanContext& vk, const core::StereoFrame& in, const core::StereoOutput& out, Logger& log);

 private:
  bool writeImage(core::VulkanContext& vk, const core::ImageRef& ref, const std::string& path, Logger& log);
  std::string dir_;
  uint32_t maxFrames_;
  uint32_t frame_ = 0;
};

}  // namespace steadyxr::layer
