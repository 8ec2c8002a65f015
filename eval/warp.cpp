#include "warp.h"

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace steadyxr::eval {

Image rotationalTimewarp(const Image& source, const EyeCamera& sourceCam, const EyeCamera& displayCam) {
  Image out(displayCam.width, displayCam.height);
  for (int y = 0; y < out.height; ++y) {
    for (int x = 0; x < out.width; ++x) {
      const glm::vec3 dir = pixelDirection(displayCam, x + 0.5f, y + 0.5f);
      glm::vec2 p;
      float c[3];
      if (projectDirection(sourceCam, dir, &p) && sampleBilinear(source, p.x, p.y, c)) {
        std::copy_n(c, 3, out.at(x, y));
      }
    }
  }
  return out;
}

Image forwardDepthWarp(const Image& source, const DepthMap& depth, const EyeCamera& sourceCam,
                       const EyeCamera& displayCam, const MotionField& motion, float fraction) {
  const int w = displayCam.width, h = displayCam.height;
  Image out(w, h);
  std::vector<float> zbuf(static_cast<size_t>(w) * h, std::numeric_limits<float>::infinity());
  for (int y = 0; y < source.height; ++y) {
    for (int x = 0; x < source.width; ++x) {
      glm::vec3 p = unproject(sourceCam, x + 0.5f, y + 0.5f, depth.at(x, y));
      if (motion) p += fraction * motion(p);
      glm::vec2 q;
      float z = 0.0f;
      if (!project(displayCam, p, &q, &z)) continue;
      const int qx = static_cast<int>(std::floor(q.x)), qy = static_cast<int>(std::floor(q.y));
      if (qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
      float& zb = zbuf[static_cast<size_t>(qy) * w + qx];
      if (z < zb) {
        zb = z;
        std::copy_n(source.at(x, y), 3, out.at(qx, qy));
      }
    }
  }
  // One-pixel gap filling: take the nearest (smallest depth) written 4-neighbour.
  Image filled = out;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (std::isfinite(zbuf[static_cast<size_t>(y) * w + x])) continue;
      float best = std::numeric_limits<float>::infinity();
      const int nx[4] = {x - 1, x + 1, x, x}, ny[4] = {y, y, y - 1, y + 1};
      for (int i = 0; i < 4; ++i) {
        if (nx[i] < 0 || ny[i] < 0 || nx[i] >= w || ny[i] >= h) continue;
        const float z = zbuf[static_cast<size_t>(ny[i]) * w + nx[i]];
        if (z < best) {
          best = z;
          std::copy_n(out.at(nx[i], ny[i]), 3, filled.at(x, y));
        }
      }
    }
  }
  return filled;
}

}  // namespace steadyxr::eval
