#include "warp.h"

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace steadyxr::eval {

namespace {

// The rotation-only warp is a homography between pixel grids: display pixel -> view direction
// (inverse projection at a fixed depth is linear in homogeneous 2D) -> rotate -> source pixel.
glm::mat3 rotationHomography(const EyeCamera& src, const EyeCamera& dst) {
  const glm::mat3 toNdc(glm::vec3(2.0f / dst.width, 0, 0), glm::vec3(0, 2.0f / dst.height, 0),
                        glm::vec3(-1, -1, 1));
  const glm::mat4 invProj = glm::inverse(dst.proj);
  const float z0 = 0.5f;
  const glm::mat3 ndcToDir{glm::vec3(invProj[0]), glm::vec3(invProj[1]),
                           glm::vec3(invProj[2] * z0 + invProj[3])};
  const glm::mat3 rot = glm::mat3_cast(glm::inverse(src.pose.orientation) * dst.pose.orientation);
  // Rows x, y, w of the source projection (x and y of a perspective projection ignore translation).
  const glm::mat4& p = src.proj;
  const glm::mat3 proj3(glm::vec3(p[0][0], p[0][1], p[0][3]), glm::vec3(p[1][0], p[1][1], p[1][3]),
                        glm::vec3(p[2][0], p[2][1], p[2][3]));
  const glm::mat3 toPixel(glm::vec3(0.5f * src.width, 0, 0), glm::vec3(0, 0.5f * src.height, 0),
                          glm::vec3(0.5f * src.width, 0.5f * src.height, 1));
  return toPixel * proj3 * rot * ndcToDir * toNdc;
}

}  // namespace

Image rotationalTimewarp(const Image& source, const EyeCamera& sourceCam, const EyeCamera& displayCam) {
  Image out(displayCam.width, displayCam.height);
  const glm::mat3 h = rotationHomography(sourceCam, displayCam);
  // The sign of the homogeneous w at the centre tells which side is in front.
  const float sign = (h * glm::vec3(0.5f * out.width, 0.5f * out.height, 1.0f)).z >= 0.0f ? 1.0f : -1.0f;
  for (int y = 0; y < out.height; ++y) {
    for (int x = 0; x < out.width; ++x) {
      const glm::vec3 q = h * glm::vec3(x + 0.5f, y + 0.5f, 1.0f);
      if (q.z * sign <= 1e-8f) continue;
      float c[3];
      if (sampleBilinear(source, q.x / q.z, q.y / q.z, c)) std::copy_n(c, 3, out.at(x, y));
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
