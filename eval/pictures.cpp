#include "pictures.h"

#include "font.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace steadyxr::eval {

namespace {

// The image viewer's picture plane is 1.2 m tall at 1.5 m (scene.cpp, picturePlane) and the eye's
// vertical fov spans tan(0.80) + tan(0.84) (eye_rig.cpp, eyeFov): it covers this fraction of the
// image height. Pictures are 4:3, the plane's aspect.
constexpr double kPlaneHeightFraction = 1.2 / (1.5 * 2.1452);  // tan(0.80) + tan(0.84) = 2.1452

Rgba8 blank(int w, int h) {
  Rgba8 img;
  img.width = w;
  img.height = h;
  img.pixels.assign(size_t(w) * h * 4, 255);
  return img;
}

void set(Rgba8* img, int x, int y, double v) {
  const uint8_t b = uint8_t(std::lround(std::clamp(v, 0.0, 1.0) * 255.0));
  uint8_t* p = &img->pixels[(size_t(y) * img->width + x) * 4];
  p[0] = p[1] = p[2] = b;
}

// Light and dark of the line pictures (display values): 0.9 and 0.12, high contrast without
// clipping (as printed line art).
constexpr double kLight = 0.9, kDark = 0.12;

}  // namespace

const std::vector<std::string>& proceduralPictureNames() {
  static const std::vector<std::string> names = {"zoneplate", "lines1px", "hatch", "smalltext",
                                                 "darkgradient"};
  return names;
}

bool isProceduralPicture(const std::string& name) {
  const auto& n = proceduralPictureNames();
  return std::find(n.begin(), n.end(), name) != n.end();
}

Rgba8 proceduralPicture(const std::string& name, int screenHeight) {
  const int h = std::max(16, int(std::lround(kPlaneHeightFraction * screenHeight)));
  const int w = h * 4 / 3;
  Rgba8 img = blank(w, h);
  const double cx = 0.5 * w, cy = 0.5 * h, rMax = std::sqrt(cx * cx + cy * cy);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      double v = kLight;
      if (name == "zoneplate") {
        // Local frequency f(r) = 0.5 r / rMax cycles per pixel: phase 2 pi * integral = pi r^2 / (2 rMax).
        const double dx = x + 0.5 - cx, dy = y + 0.5 - cy;
        v = 0.5 + 0.5 * std::cos(std::numbers::pi * (dx * dx + dy * dy) / (2.0 * rMax));
      } else if (name == "lines1px") {
        v = (x % 3 == 0 || y % 3 == 0) ? kDark : kLight;
      } else if (name == "hatch") {
        v = ((x < w / 2 ? x + y : x - y + 4 * h) % 4 == 0) ? kDark : kLight;
      } else if (name == "darkgradient") {
        v = 0.16 * (x + 0.5) / w;
      }
      set(&img, x, y, v);
    }
  }
  if (name == "smalltext") {
    Image page(w, h, float(kLight));
    const float ink[3] = {float(kDark), float(kDark), float(kDark)};
    const char* lines[] = {"THE QUICK BROWN FOX JUMPS OVER",
                           "THE LAZY DOG 0123456789 +-=.,:", "PACK MY BOX WITH FIVE DOZEN",
                           "LIQUOR JUGS (42%) X/Y @ 90 HZ"};
    for (int row = 0, y = 1; y + kGlyphHeight <= h; ++row, y += kGlyphHeight + 2) {
      drawText(&page, lines[row % 4], 1 - (row * 7) % 11, y, ink);  // rows offset: no vertical alignment
    }
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) set(&img, x, y, page.at(x, y)[0]);
    }
  }
  return img;
}

std::string pictureClass(const std::string& name) {
  if (name == "darkgradient") return "dark";
  if (isProceduralPicture(name)) return "synthetic";
  if (name == "brick" || name == "grass" || name == "gravel") return "texture";
  return "photo";
}

}  // namespace steadyxr::eval
