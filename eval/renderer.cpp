// SceneRenderer's public side: the 1-sample, MSAA and ground-truth renders, readback of the filter's
// outputs, and the image references handed to the filter.
#include "renderer.h"

#include "renderer_impl.h"
#include "truth_samples.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

#include <glm/gtc/matrix_transform.hpp>

namespace steadyxr::eval {

// Records the draws of one view; `jitter` is in pixels.
void SceneRenderer::Impl::recordDraws(const EyeCamera& cam, const DrawList& draws, glm::vec2 jitter,
                                      float weight, bool noise) {
  const glm::mat4 shift =
      glm::translate(glm::mat4(1.0f), glm::vec3(2.0f * jitter.x / width, 2.0f * jitter.y / height, 0.0f));
  const glm::mat4 vp = shift * cam.viewProj;
  for (const DrawQuad& q : draws.quads) {
    PushConstants pc{};
    pc.mvp = vp * q.model;
    pc.tint = glm::vec4(glm::vec3(q.tint), weight);
    pc.uvST = q.uvST;
    pc.noise = noise ? glm::vec4(draws.noiseAmplitude, float(draws.noiseSeed % 16777216u), 0.0f, 0.0f)
                     : glm::vec4(0.0f);
    const uint32_t t = std::min<uint32_t>(q.texture, uint32_t(textureSets.size() - 1));
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipelineLayout.get(), 0, 1, &textureSets[t],
                            0, nullptr);
    vkCmdPushConstants(cmd, pipelineLayout.get(), VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT,
                       0, sizeof(pc), &pc);
    vkCmdDraw(cmd, 6, 1, 0, 0);
  }
}

void SceneRenderer::Impl::beginPass(VkRenderPass rp, VkFramebuffer fb, VkPipeline pipeline, glm::vec3 clear,
                                    bool accumulate) {
  std::array<VkClearValue, 3> cv{};
  cv[0].color = accumulate ? VkClearColorValue{{0.0f, 0.0f, 0.0f, 0.0f}}
                           : VkClearColorValue{{clear.r, clear.g, clear.b, 1.0f}};
  cv[1].depthStencil = {1.0f, 0};
  VkRenderPassBeginInfo bi{};
  bi.sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO;
  bi.renderPass = rp;
  bi.framebuffer = fb;
  bi.renderArea = {{0, 0}, {uint32_t(width), uint32_t(height)}};
  bi.clearValueCount = 3;
  bi.pClearValues = cv.data();
  vkCmdBeginRenderPass(cmd, &bi, VK_SUBPASS_CONTENTS_INLINE);
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
}

SceneRenderer::SceneRenderer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
SceneRenderer::~SceneRenderer() {
  if (impl_) vkDeviceWaitIdle(impl_->dev);
}

std::unique_ptr<SceneRenderer> SceneRenderer::create(core::VulkanContext& context, int width, int height,
                                                     const std::vector<Rgba8>& textures,
                                                     RenderOptions options, std::string* error) {
  auto impl = std::make_unique<Impl>(context, width, height, options);
  if (!impl->init(textures, error)) return nullptr;
  return std::unique_ptr<SceneRenderer>(new SceneRenderer(std::move(impl)));
}

bool SceneRenderer::renderBase(int eye, const EyeCamera& cam, const DrawList& draws, RenderedView* out,
                               double* gpuMs, std::string* error) {
  Impl& m = *impl_;
  if (!m.beginImpl(error)) return false;
  if (m.timestamps) vkCmdResetQueryPool(m.cmd, m.queries.get(), 0, 2);
  m.timestamp(0, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT);
  m.beginPass(m.basePass.get(), m.baseFb[eye].get(), m.basePipeline.get(), draws.clearColor, false);
  m.recordDraws(cam, draws, glm::vec2(0.0f), 1.0f, true);
  vkCmdEndRenderPass(m.cmd);
  m.timestamp(1, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT);
  m.globalBarrier(VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                  VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_SHADER_READ_BIT);
  const VkDeviceSize depthOffset = VkDeviceSize(m.width) * m.height * 4;
  m.copyToStaging(m.baseColor[eye].image.get(), VK_IMAGE_ASPECT_COLOR_BIT, 0);
  m.copyToStaging(m.baseDepth[eye].image.get(), VK_IMAGE_ASPECT_DEPTH_BIT, depthOffset);
  m.hostBarrier();
  if (!m.submitAndWait(error)) return false;
  m.readTimestamps(gpuMs);
  out->color = m.stagingColor8();
  out->depth.width = m.width;
  out->depth.height = m.height;
  const float* d = reinterpret_cast<const float*>(static_cast<const uint8_t*>(m.stagingPtr) + depthOffset);
  out->depth.depth.assign(d, d + size_t(m.width) * m.height);
  return true;
}

bool SceneRenderer::supportsSamples(int samples) const {
  return samples == 1 || ((samples == 2 || samples == 4) && impl_->msaaSupported[samples == 2 ? 0 : 1]);
}

bool SceneRenderer::renderMsaa(int samples, int eye, const EyeCamera& cam, const DrawList& draws, Image* out,
                               double* gpuMs, std::string* error) {
  Impl& m = *impl_;
  const int i = samples == 2 ? 0 : 1;
  if (!supportsSamples(samples)) {
    *error = std::to_string(samples) + "x MSAA is not supported by this device";
    return false;
  }
  if (!m.beginImpl(error)) return false;
  if (m.timestamps) vkCmdResetQueryPool(m.cmd, m.queries.get(), 0, 2);
  m.timestamp(0, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT);
  m.beginPass(m.msaaPass[i].get(), m.msaaFb[i][eye].get(), m.msaaPipeline[i].get(), draws.clearColor, false);
  m.recordDraws(cam, draws, glm::vec2(0.0f), 1.0f, true);
  vkCmdEndRenderPass(m.cmd);
  m.timestamp(1, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT);
  m.globalBarrier(VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
                  VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_SHADER_READ_BIT);
  m.copyToStaging(m.msaaResolve[i][eye].image.get(), VK_IMAGE_ASPECT_COLOR_BIT, 0);
  m.hostBarrier();
  if (!m.submitAndWait(error)) return false;
  m.readTimestamps(gpuMs);
  *out = m.stagingColor8();
  return true;
}

bool SceneRenderer::renderApp(int samples, int eye, const EyeCamera& cam, const DrawList& draws,
                              RenderedView* out, double* gpuMs, std::string* error, Image* oneSampleColor) {
  if (!renderBase(eye, cam, draws, out, gpuMs, error)) return false;
  if (samples == 1) return true;
  if (oneSampleColor) *oneSampleColor = out->color;
  return renderMsaa(samples, eye, cam, draws, &out->color, gpuMs, error);
}

bool SceneRenderer::renderGroundTruth(const EyeCamera& cam, const DrawList& draws, int gridSize, Image* out,
                                      std::string* error) {
  Impl& m = *impl_;
  if (!m.beginImpl(error)) return false;
  m.beginPass(m.gtPass.get(), m.gtFb.get(), m.gtPipeline.get(), draws.clearColor, true);
  const float weight = 1.0f / float(gridSize * gridSize);
  // Additive accumulation only hides what is behind when the nearest surface is drawn first:
  // front to back by the view depth of each quad's centre (the scenes' quads do not intersect).
  DrawList sorted = draws;
  std::stable_sort(sorted.quads.begin(), sorted.quads.end(), [&](const DrawQuad& a, const DrawQuad& b) {
    return (cam.view * a.model[3]).z > (cam.view * b.model[3]).z;
  });
  for (int sy = 0; sy < gridSize; ++sy) {
    for (int sx = 0; sx < gridSize; ++sx) {
      if (sx + sy > 0) {
        // Each jittered sub-render needs its own depth test.
        VkClearAttachment ca{VK_IMAGE_ASPECT_DEPTH_BIT, 0, {}};
        ca.clearValue.depthStencil = {1.0f, 0};
        VkClearRect rect{{{0, 0}, {uint32_t(m.width), uint32_t(m.height)}}, 0, 1};
        vkCmdClearAttachments(m.cmd, 1, &ca, 1, &rect);
      }
      const glm::vec2 jitter = truthSampleOffset(sx, sy, gridSize);
      // The background colour is accumulated as a full-screen quad behind everything.
      DrawList bg;
      DrawQuad q;
      q.model = glm::inverse(cam.viewProj) * glm::translate(glm::mat4(1.0f), glm::vec3(0.0f, 0.0f, 0.999f)) *
                glm::scale(glm::mat4(1.0f), glm::vec3(4.0f, 4.0f, 1.0f));
      q.texture = 0;
      q.tint = glm::vec4(draws.clearColor, 1.0f);
      bg.quads.push_back(q);
      m.recordDraws(cam, sorted, jitter, weight, false);
      m.recordDraws(cam, bg, jitter, weight, false);
    }
  }
  vkCmdEndRenderPass(m.cmd);
  m.globalBarrier(VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT, VK_ACCESS_TRANSFER_READ_BIT);
  m.copyToStaging(m.gtColor.image.get(), VK_IMAGE_ASPECT_COLOR_BIT, 0);
  m.hostBarrier();
  if (!m.submitAndWait(error)) return false;
  Image img(m.width, m.height);
  const size_t n = size_t(m.width) * m.height;
  if (m.accumFormat == VK_FORMAT_R32G32B32A32_SFLOAT) {
    const float* p = static_cast<const float*>(m.stagingPtr);
    for (size_t i = 0; i < n; ++i) {
      for (int c = 0; c < 3; ++c) {
        // Averaged in linear light when sRGB; the metrics compare display-encoded values.
        const float v = std::clamp(p[i * 4 + c], 0.0f, 1.0f);
        img.rgb[i * 3 + c] = m.options.srgb ? linearToSrgb(v) : v;
      }
    }
  } else {
    *error = "ground truth needs a blendable R32G32B32A32_SFLOAT target";
    return false;
  }
  *out = std::move(img);
  return true;
}

bool SceneRenderer::readOutput(int eye, Image* out, std::string* error) {
  Impl& m = *impl_;
  if (!m.beginImpl(error)) return false;
  m.globalBarrier(VK_ACCESS_MEMORY_WRITE_BIT, VK_ACCESS_TRANSFER_READ_BIT);
  m.copyToStaging(m.outputs[eye].image.get(), VK_IMAGE_ASPECT_COLOR_BIT, 0);
  m.hostBarrier();
  if (!m.submitAndWait(error)) return false;
  *out = m.stagingColor8();
  return true;
}

namespace {
core::ImageRef refOf(const GpuImage& img, int w, int h) {
  core::ImageRef r;
  r.image = img.image.get();
  r.format = img.format;
  r.extent = {uint32_t(w), uint32_t(h)};
  r.rect = {{0, 0}, {uint32_t(w), uint32_t(h)}};
  r.usage = img.usage;
  r.layout = VK_IMAGE_LAYOUT_GENERAL;
  r.finalLayout = VK_IMAGE_LAYOUT_GENERAL;
  r.mutableFormat = img.mutableFormat;
  return r;
}
}  // namespace

core::ImageRef SceneRenderer::baseColor(int eye) const {
  return refOf(impl_->baseColor[eye], impl_->width, impl_->height);
}
core::DepthRef SceneRenderer::baseDepth(int eye, float nearZ, float farZ) const {
  core::DepthRef d;
  d.image = refOf(impl_->baseDepth[eye], impl_->width, impl_->height);
  d.nearZ = nearZ;
  d.farZ = farZ;
  return d;
}
core::ImageRef SceneRenderer::msaaColor(int samples, int eye) const {
  return refOf(impl_->msaaResolve[samples == 2 ? 0 : 1][eye], impl_->width, impl_->height);
}
core::ImageRef SceneRenderer::colorOf(int samples, int eye) const {
  return samples == 1 ? baseColor(eye) : msaaColor(samples, eye);
}
core::ImageRef SceneRenderer::output(int eye) const {
  return refOf(impl_->outputs[eye], impl_->width, impl_->height);
}

}  // namespace steadyxr::eval
