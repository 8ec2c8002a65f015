#include "gpu_image.h"

#include <cmath>
#include <cstring>
#include <stdexcept>

#include <glm/gtc/packing.hpp>
#include <glm/gtc/type_precision.hpp>

namespace steadyxr::test {
namespace {

uint32_t texelSize(VkFormat f) {
  return f == VK_FORMAT_R16G16B16A16_SFLOAT ? 8 : 4;
}
bool srgb(VkFormat f) {
  return f == VK_FORMAT_R8G8B8A8_SRGB || f == VK_FORMAT_B8G8R8A8_SRGB;
}
bool bgra(VkFormat f) {
  return f == VK_FORMAT_B8G8R8A8_UNORM || f == VK_FORMAT_B8G8R8A8_SRGB;
}
bool depth(VkFormat f) {
  return f == VK_FORMAT_D32_SFLOAT;
}

float toSrgb(float c) {
  return float(srgbEncode(c));
}
float fromSrgb(float c) {
  return float(srgbDecode(c));
}

void check(VkResult r, const char* what) {
  if (r != VK_SUCCESS) throw std::runtime_error(std::string(what) + " failed: " + std::to_string(r));
}

}  // namespace

GpuImage::GpuImage(core::VulkanContext& ctx, VkFormat format, uint32_t width, uint32_t height,
                   uint32_t layers, VkImageUsageFlags usage, bool mutableFormat)
    : ctx_(ctx),
      format_(format),
      width_(width),
      height_(height),
      layers_(layers),
      usage_(usage),
      mutable_(mutableFormat) {
  VkImageCreateInfo ici{};
  ici.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
  // EXTENDED_USAGE: STORAGE is valid for the UNORM view of an SRGB image (the core writes through it).
  ici.flags = mutableFormat ? VK_IMAGE_CREATE_MUTABLE_FORMAT_BIT | VK_IMAGE_CREATE_EXTENDED_USAGE_BIT : 0;
  ici.imageType = VK_IMAGE_TYPE_2D;
  ici.format = format;
  ici.extent = {width, height, 1};
  ici.mipLevels = 1;
  ici.arrayLayers = layers;
  ici.samples = VK_SAMPLE_COUNT_1_BIT;
  ici.tiling = VK_IMAGE_TILING_OPTIMAL;
  ici.usage = usage | VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  ici.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  check(vkCreateImage(ctx.device(), &ici, nullptr, &image_), "vkCreateImage");
  VkMemoryRequirements req;
  vkGetImageMemoryRequirements(ctx.device(), image_, &req);
  VkMemoryAllocateInfo mai{};
  mai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
  mai.allocationSize = req.size;
  mai.memoryTypeIndex = ctx.findMemoryType(req.memoryTypeBits, 0, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  check(vkAllocateMemory(ctx.device(), &mai, nullptr, &memory_), "vkAllocateMemory");
  vkBindImageMemory(ctx.device(), image_, memory_, 0);
}

GpuImage::~GpuImage() {
  vkDestroyImage(ctx_.device(), image_, nullptr);
  vkFreeMemory(ctx_.device(), memory_, nullptr);
}

core::ImageRef GpuImage::ref(uint32_t layer, VkImageLayout layout, VkRect2D rect) const {
  core::ImageRef r;
  r.image = image_;
  r.format = format_;
  r.extent = {width_, height_};
  r.arrayLayer = layer;
  r.arrayLayerCount = layers_;
  r.rect = rect.extent.width ? rect : VkRect2D{{0, 0}, {width_, height_}};
  r.usage = usage_ | VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  r.mutableFormat = mutable_;
  r.layout = layout;
  return r;
}

void GpuImage::runOnce(const std::function<void(VkCommandBuffer)>& record) {
  VkDevice d = ctx_.device();
  VkCommandPoolCreateInfo cpci{};
  cpci.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
  cpci.queueFamilyIndex = ctx_.queueFamilyIndex();
  VkCommandPool pool;
  check(vkCreateCommandPool(d, &cpci, nullptr, &pool), "vkCreateCommandPool");
  VkCommandBufferAllocateInfo cbai{};
  cbai.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
  cbai.commandPool = pool;
  cbai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  cbai.commandBufferCount = 1;
  VkCommandBuffer cmd;
  vkAllocateCommandBuffers(d, &cbai, &cmd);
  VkCommandBufferBeginInfo bi{};
  bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  vkBeginCommandBuffer(cmd, &bi);
  record(cmd);
  vkEndCommandBuffer(cmd);
  VkSubmitInfo si{};
  si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cmd;
  check(vkQueueSubmit(ctx_.queue(), 1, &si, VK_NULL_HANDLE), "vkQueueSubmit");
  vkQueueWaitIdle(ctx_.queue());
  vkDestroyCommandPool(d, pool, nullptr);
}

namespace {
struct Staging {
  VkDevice device;
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  void* data = nullptr;
  Staging(core::VulkanContext& ctx, VkDeviceSize size) : device(ctx.device()) {
    VkBufferCreateInfo bci{};
    bci.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    bci.size = size;
    bci.usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    check(vkCreateBuffer(device, &bci, nullptr, &buffer), "vkCreateBuffer");
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device, buffer, &req);
    VkMemoryAllocateInfo mai{};
    mai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    mai.allocationSize = req.size;
    mai.memoryTypeIndex = ctx.findMemoryType(
        req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT,
        VK_MEMORY_PROPERTY_HOST_CACHED_BIT);
    check(vkAllocateMemory(device, &mai, nullptr, &memory), "vkAllocateMemory");
    vkBindBufferMemory(device, buffer, memory, 0);
    vkMapMemory(device, memory, 0, VK_WHOLE_SIZE, 0, &data);
  }
  ~Staging() {
    vkDestroyBuffer(device, buffer, nullptr);
    vkFreeMemory(device, memory, nullptr);
  }
};

VkImageMemoryBarrier barrier(VkImage image, VkFormat f, VkImageLayout from, VkImageLayout to,
                             uint32_t layers) {
  VkImageMemoryBarrier b{};
  b.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
  b.srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT;
  b.dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
  b.oldLayout = from;
  b.newLayout = to;
  b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.image = image;
  b.subresourceRange = {
      static_cast<VkImageAspectFlags>(depth(f) ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT), 0, 1,
      0, layers};
  return b;
}
void cmdBarrier(VkCommandBuffer cmd, const VkImageMemoryBarrier& b) {
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 0,
                       nullptr, 0, nullptr, 1, &b);
}
}  // namespace

void GpuImage::transition(VkImageLayout from, VkImageLayout to) {
  runOnce([&](VkCommandBuffer cmd) { cmdBarrier(cmd, barrier(image_, format_, from, to, layers_)); });
}

void GpuImage::upload(const HostImage& img, uint32_t layer, VkImageLayout layout, uint32_t x0, uint32_t y0) {
  const uint32_t ts = texelSize(format_);
  Staging st(ctx_, VkDeviceSize(img.width) * img.height * ts);
  auto* bytes = static_cast<uint8_t*>(st.data);
  for (size_t i = 0; i < img.px.size(); ++i) {
    glm::vec4 c = img.px[i];
    if (depth(format_)) {
      std::memcpy(bytes + i * 4, &c.r, 4);
    } else if (format_ == VK_FORMAT_R16G16B16A16_SFLOAT) {
      const glm::u16vec4 h(glm::packHalf1x16(c.r), glm::packHalf1x16(c.g), glm::packHalf1x16(c.b),
                           glm::packHalf1x16(c.a));
      std::memcpy(bytes + i * 8, &h, 8);
    } else {
      if (srgb(format_)) c = {toSrgb(c.r), toSrgb(c.g), toSrgb(c.b), c.a};
      if (bgra(format_)) c = {c.b, c.g, c.r, c.a};
      for (int k = 0; k < 4; ++k)
        bytes[i * 4 + k] = static_cast<uint8_t>(std::lround(std::clamp(c[k], 0.0f, 1.0f) * 255.0f));
    }
  }
  runOnce([&](VkCommandBuffer cmd) {
    cmdBarrier(cmd, barrier(image_, format_, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                            layers_));
    VkBufferImageCopy r{};
    r.imageSubresource = {static_cast<VkImageAspectFlags>(depth(format_) ? VK_IMAGE_ASPECT_DEPTH_BIT
                                                                         : VK_IMAGE_ASPECT_COLOR_BIT),
                          0, layer, 1};
    r.imageOffset = {static_cast<int32_t>(x0), static_cast<int32_t>(y0), 0};
    r.imageExtent = {img.width, img.height, 1};
    vkCmdCopyBufferToImage(cmd, st.buffer, image_, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &r);
    cmdBarrier(cmd, barrier(image_, format_, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, layout, layers_));
  });
}

HostImage GpuImage::download(uint32_t layer, VkImageLayout layout, uint32_t x0, uint32_t y0, uint32_t w,
                             uint32_t h) {
  const uint32_t ts = texelSize(format_);
  Staging st(ctx_, VkDeviceSize(w) * h * ts);
  runOnce([&](VkCommandBuffer cmd) {
    cmdBarrier(cmd, barrier(image_, format_, layout, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, layers_));
    VkBufferImageCopy r{};
    r.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, layer, 1};
    r.imageOffset = {static_cast<int32_t>(x0), static_cast<int32_t>(y0), 0};
    r.imageExtent = {w, h, 1};
    vkCmdCopyImageToBuffer(cmd, image_, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, st.buffer, 1, &r);
    cmdBarrier(cmd, barrier(image_, format_, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, layout, layers_));
  });
  HostImage out(w, h);
  const auto* bytes = static_cast<const uint8_t*>(st.data);
  for (size_t i = 0; i < out.px.size(); ++i) {
    glm::vec4 c;
    if (format_ == VK_FORMAT_R16G16B16A16_SFLOAT) {
      glm::u16vec4 v;
      std::memcpy(&v, bytes + i * 8, 8);
      c = {glm::unpackHalf1x16(v.x), glm::unpackHalf1x16(v.y), glm::unpackHalf1x16(v.z),
           glm::unpackHalf1x16(v.w)};
    } else {
      for (int k = 0; k < 4; ++k) c[k] = bytes[i * 4 + k] / 255.0f;
      if (bgra(format_)) c = {c.b, c.g, c.r, c.a};
      if (srgb(format_)) c = {fromSrgb(c.r), fromSrgb(c.g), fromSrgb(c.b), c.a};
    }
    out.px[i] = c;
  }
  return out;
}

}  // namespace steadyxr::test
