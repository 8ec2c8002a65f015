// The harness's minimal scene rasteriser: textured quads with a depth buffer, one vertex +
// fragment shader pair, rendered at 1 sample per pixel (the "app" image the filter gets),
// with MSAA 2x/4x (same pipeline, multisampled target resolved), and as ground truth
// (N x N jittered 1-sample renders, truth_samples.h, accumulated in a float target).
#pragma once

#include "camera.h"
#include "image.h"

#include "steadyxr/core/frame.h"
#include "steadyxr/core/vulkan_context.h"

#include <memory>
#include <string>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace steadyxr::eval {

struct DrawQuad {
  glm::mat4 model{1.0f};  // maps the unit quad [-0.5, 0.5]^2 (z = 0) to world
  uint32_t texture = 0;
  glm::vec4 tint{1.0f};  // rgb only; alpha is set by the renderer
  glm::vec4 uvST{1.0f, 1.0f, 0.0f, 0.0f};
};

struct DrawList {
  std::vector<DrawQuad> quads;
  glm::vec3 clearColor{0.2f};
  float noiseAmplitude = 0.0f;  // per-pixel noise (noisy scene variant); 0 = none
  uint32_t noiseSeed = 0;
};

struct RenderedView {
  Image color;
  DepthMap depth;
};

struct RenderOptions {
  bool srgb = true;     // sRGB eye images and textures (real swapchains are sRGB); false: UNORM
  bool mipmaps = true;  // trilinear mipmapped textures (as real apps); false: base level only
};

class SceneRenderer {
 public:
  static std::unique_ptr<SceneRenderer> create(core::VulkanContext& context, int width, int height,
                                               const std::vector<Rgba8>& textures, RenderOptions options,
                                               std::string* error);
  ~SceneRenderer();
  SceneRenderer(const SceneRenderer&) = delete;
  SceneRenderer& operator=(const SceneRenderer&) = delete;

  // 1 sample per pixel into eye `eye`'s persistent target (left in GENERAL for the filter).
  // gpuMs gets the render's GPU time (timestamps) when supported, else stays unchanged.
  bool renderBase(int eye, const EyeCamera& cam, const DrawList& draws, RenderedView* out, double* gpuMs,
                  std::string* error);
  bool supportsSamples(int samples) const;  // framebuffer colour and depth sample counts
  // samples = 2 or 4; resolved into eye `eye`'s MSAA target of that sample count.
  bool renderMsaa(int samples, int eye, const EyeCamera& cam, const DrawList& draws, Image* out,
                  double* gpuMs, std::string* error);
  // The app's own image: the 1-sample render's depth (an app resolves depth from one sample) and, for
  // samples 2 or 4 (--app-msaa), the colour of that MSAA render resolved; colorOf(samples, eye) holds it.
  // oneSampleColor (optional, samples > 1): the 1-sample render's colour as well.
  bool renderApp(int samples, int eye, const EyeCamera& cam, const DrawList& draws, RenderedView* out,
                 double* gpuMs, std::string* error, Image* oneSampleColor = nullptr);
  // gridSize x gridSize renders offset by N-rooks (truth_samples.h), box-filtered in linear light
  // when sRGB (noise is never added); returned display-encoded like every other image.
  bool renderGroundTruth(const EyeCamera& cam, const DrawList& draws, int gridSize, Image* out,
                         std::string* error);
  // Reads one of the filter output images back.
  bool readOutput(int eye, Image* out, std::string* error);

  core::ImageRef baseColor(int eye) const;
  core::DepthRef baseDepth(int eye, float nearZ, float farZ) const;
  core::ImageRef msaaColor(int samples, int eye) const;
  core::ImageRef colorOf(int samples, int eye) const;  // baseColor for 1 sample, else msaaColor
  core::ImageRef output(int eye) const;                // RGBA8 UNORM storage images the filter writes

  struct Impl;

 private:
  explicit SceneRenderer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace steadyxr::eval
