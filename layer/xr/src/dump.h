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
  // Each dumper (one per session) names its files with a tag of its own, p<pid>s<n>, so that
  // sessions (and processes) sharing the folder never overwrite each other's images.
  ImageDumper(std::string dir, uint32_t maxFrames);
  bool wants() const { return !disabled_ && frame_ < maxFrames_; }
  // Writes <dir>/frame<NNNN>_<tag>_<view>_{in,out}.png for each view; call after the filter's
  // submit, before the output images are released. A folder that cannot be created (or is not
  // a folder) disables the dumper with one log line, before anything is read back.
  void dump(core::VulkanContext& vk, const core::StereoFrame& in, const core::StereoOutput& out, Logger& log);
  const std::string& tag() const { return tag_; }

 private:
  bool writeImage(core::VulkanContext& vk, const core::ImageRef& ref, const std::string& path, Logger& log);
  std::string dir_;
  std::string tag_;
  uint32_t maxFrames_;
  uint32_t frame_ = 0;
  bool disabled_ = false;
  bool folderChecked_ = false;
};

}  // namespace steadyxr::layer
