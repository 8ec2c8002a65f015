#include "image.h"

#include <algorithm>
#include <array>
#include <cmath>

#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_WRITE_IMPLEMENTATION
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wshadow"
#include <stb/stb_image.h>
#include <stb/stb_image_write.h>
#pragma GCC diagnostic pop

namespace steadyxr::eval {

bool loadPng(const std::string& path, Rgba8* out, std::string* error) {
  int w = 0, h = 0, channels = 0;
  stbi_uc* data = stbi_load(path.c_str(), &w, &h, &channels, 4);
  if (data == nullptr) {
    if (error) *error = "cannot load image '" + path + "': " + stbi_failure_reason();
    return false;
  }
  out->width = w;
  out->height = h;
  out->pixels.assign(data, data + static_cast<size_t>(w) * h * 4);
  stbi_image_free(data);
  return true;
}

bool savePng(const std::string& path, const Image& image, std::string* error) {
  std::vector<uint8_t> bytes(static_cast<size_t>(image.width) * image.height * 3);
  for (size_t i = 0; i < bytes.size(); ++i) {
    bytes[i] = static_cast<uint8_t>(std::lround(std::clamp(image.rgb[i], 0.0f, 1.0f) * 255.0f));
  }
  if (stbi_write_png(path.c_str(), image.width, image.height, 3, bytes.data(), image.width * 3) == 0) {
    if (error) *error = "cannot write '" + path + "'";
    return false;
  }
  return true;
}

Image fromRgba8(const uint8_t* rgba, int width, int height) {
  Image img(width, height);
  for (size_t i = 0, n = static_cast<size_t>(width) * height; i < n; ++i) {
    for (int c = 0; c < 3; ++c) img.rgb[i * 3 + c] = rgba[i * 4 + c] / 255.0f;
  }
  return img;
}

bool sampleBilinear(const Image& image, float fx, float fy, float out[3]) {
  const float x = fx - 0.5f, y = fy - 0.5f;
  if (!(x > -0.5f && y > -0.5f && x < image.width - 0.5f && y < image.height - 0.5f)) return false;
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  const float tx = x - x0, ty = y - y0;
  const int xa = std::clamp(x0, 0, image.width - 1), xb = std::clamp(x0 + 1, 0, image.width - 1);
  const int ya = std::clamp(y0, 0, image.height - 1), yb = std::clamp(y0 + 1, 0, image.height - 1);
  const float* p00 = image.at(xa, ya);
  const float* p10 = image.at(xb, ya);
  const float* p01 = image.at(xa, yb);
  const float* p11 = image.at(xb, yb);
  for (int c = 0; c < 3; ++c) {
    const float top = p00[c] + (p10[c] - p00[c]) * tx;
    const float bottom = p01[c] + (p11[c] - p01[c]) * tx;
    out[c] = top + (bottom - top) * ty;
  }
  return true;
}

Image resampled(const Image& image, int w, int h) {
  Image out(w, h);
  const float sx = float(image.width) / float(w), sy = float(image.height) / float(h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      sampleBilinear(image, (float(x) + 0.5f) * sx, (float(y) + 0.5f) * sy, out.at(x, y));
  return out;
}

Image cropMagnify(const Image& image, int x0, int y0, int w, int h, int scale) {
  Image out(w * scale, h * scale);
  for (int y = 0; y < out.height; ++y) {
    for (int x = 0; x < out.width; ++x) {
      const int sx = std::clamp(x0 + x / scale, 0, image.width - 1);
      const int sy = std::clamp(y0 + y / scale, 0, image.height - 1);
      std::copy_n(image.at(sx, sy), 3, out.at(x, y));
    }
  }
  return out;
}

Image differenceImage(const Image& a, const Image& b, float gain) {
  Image out(a.width, a.height);
  for (size_t i = 0; i < out.rgb.size(); ++i)
    out.rgb[i] = std::min(1.0f, std::fabs(a.rgb[i] - b.rgb[i]) * gain);
  return out;
}

void blit(Image* canvas, const Image& tile, int x, int y) {
  for (int ty = 0; ty < tile.height; ++ty) {
    for (int tx = 0; tx < tile.width; ++tx) {
      const int cx = x + tx, cy = y + ty;
      if (cx < 0 || cy < 0 || cx >= canvas->width || cy >= canvas->height) continue;
      std::copy_n(tile.at(tx, ty), 3, canvas->at(cx, cy));
    }
  }
}

float srgbToLinear(float e) {
  return e <= 0.04045f ? e / 12.92f : std::pow((e + 0.055f) / 1.055f, 2.4f);
}

float linearToSrgb(float l) {
  return l <= 0.0031308f ? 12.92f * l : 1.055f * std::pow(l, 1.0f / 2.4f) - 0.055f;
}

std::vector<Rgba8> mipChain(const Rgba8& image, bool srgb) {
  std::vector<Rgba8> levels{image};
  std::array<float, 256> toLinear{};
  for (int v = 0; v < 256; ++v) toLinear[v] = srgb ? srgbToLinear(v / 255.0f) : v / 255.0f;
  while (levels.back().width > 1 || levels.back().height > 1) {
    const Rgba8& up = levels.back();
    Rgba8 down;
    down.width = std::max(1, up.width / 2);
    down.height = std::max(1, up.height / 2);
    down.pixels.resize(size_t(down.width) * down.height * 4);
    for (int y = 0; y < down.height; ++y) {
      for (int x = 0; x < down.width; ++x) {
        for (int c = 0; c < 4; ++c) {
          float sum = 0.0f;
          for (int k = 0; k < 4; ++k) {
            const int sx = std::min(up.width - 1, 2 * x + (k & 1)),
                      sy = std::min(up.height - 1, 2 * y + (k >> 1));
            const uint8_t v = up.pixels[(size_t(sy) * up.width + sx) * 4 + c];
            sum += c == 3 ? v / 255.0f : toLinear[v];  // alpha is linear in either format
          }
          const float mean = sum / 4.0f;
          const float enc = c == 3 || !srgb ? mean : linearToSrgb(mean);
          down.pixels[(size_t(y) * down.width + x) * 4 + c] =
              uint8_t(std::lround(std::clamp(enc, 0.0f, 1.0f) * 255.0f));
        }
      }
    }
    levels.push_back(std::move(down));
  }
  return levels;
}

}  // namespace steadyxr::eval
