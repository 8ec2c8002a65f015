// CPU images the harness reads back from the GPU and computes metrics on. Values are the
// 8-bit display-encoded (sRGB) code values scaled to [0, 1]; every metric works in that space.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace steadyxr::eval {

struct Image {
  int width = 0;
  int height = 0;
  std::vector<float> rgb;  // interleaved R, G, B; row 0 is the top

  Image() = default;
  Image(int w, int h, float fill = 0.0f) : width(w), height(h), rgb(static_cast<size_t>(w) * h * 3, fill) {}
  float* at(int x, int y) { return &rgb[(static_cast<size_t>(y) * width + x) * 3]; }
  const float* at(int x, int y) const { return &rgb[(static_cast<size_t>(y) * width + x) * 3]; }
  bool empty() const { return width == 0 || height == 0; }
};

// Non-linear depth buffer values in [0, 1] as the raster wrote them (1 = far plane).
struct DepthMap {
  int width = 0;
  int height = 0;
  std::vector<float> depth;
  float at(int x, int y) const { return depth[static_cast<size_t>(y) * width + x]; }
};

// 8-bit RGBA pixels as loaded from a PNG (alpha is kept for upload, ignored by metrics).
struct Rgba8 {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> pixels;
};

bool loadPng(const std::string& path, Rgba8* out, std::string* error);
bool savePng(const std::string& path, const Image& image, std::string* error);

Image fromRgba8(const uint8_t* rgba, int width, int height);
// Bilinear sample at continuous pixel coordinates (pixel centres at +0.5); false outside.
bool sampleBilinear(const Image& image, float fx, float fy, float out[3]);
// The image resampled to w x h over the same field of view (bilinear at each new pixel's centre);
// the identity, to the bit, at the image's own size.
Image resampled(const Image& image, int w, int h);
// Crop [x0, x0+w) x [y0, y0+h) and magnify each pixel to `scale` x `scale` (nearest).
Image cropMagnify(const Image& image, int x0, int y0, int w, int h, int scale);
// |a - b| * gain per channel, clamped to [0, 1].
Image differenceImage(const Image& a, const Image& b, float gain);
// Place `tile` into `canvas` at (x, y).
void blit(Image* canvas, const Image& tile, int x, int y);

// The sRGB transfer functions (IEC 61966-2-1), on values in [0, 1].
float srgbToLinear(float encoded);
float linearToSrgb(float linear);
// Mip levels 0 (the image itself) .. 1x1, each a 2x2 box average of the one above (odd sizes
// clamp), averaged in linear light when `srgb` (what the GPU's sRGB sampler then interpolates).
std::vector<Rgba8> mipChain(const Rgba8& image, bool srgb);

}  // namespace steadyxr::eval
