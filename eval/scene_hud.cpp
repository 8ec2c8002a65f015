#include "scene_hud.h"

#include "results.h"
#include "scene.h"

#include <algorithm>
#include <cmath>

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

namespace steadyxr::eval {

namespace {

// Metres per pixel at kHudDistanceM for a 96 px wide eye (eyeFov: tan 0.73 + tan 0.82 = 1.967).
constexpr float kMetresPerPx = kHudDistanceM * 1.967f / 96.0f;

DrawQuad headQuad(glm::vec2 centrePx, glm::vec2 sizePx, float distanceM, uint32_t texture, glm::vec3 tint) {
  DrawQuad q;
  // Lateral size kept under --ppd; only the distance grows (see hudOverlay).
  q.model = glm::translate(glm::mat4(1.0f), glm::vec3(centrePx * kMetresPerPx, -distanceM)) *
            glm::scale(glm::mat4(1.0f), glm::vec3(sizePx * kMetresPerPx, 1.0f));
  q.texture = texture;
  q.tint = glm::vec4(tint, 1.0f);
  return q;
}

}  // namespace

glm::mat4 headToWorld(const HeadPose& head) {
  return glm::translate(glm::mat4(1.0f), head.position) * glm::mat4_cast(head.orientation);
}

std::vector<DrawQuad> hudOverlay(const TextureSet& textures, double fovTangentScale) {
  const float distance = float(kHudDistanceM / fovTangentScale);
  // A bright reticle (a HUD's usual yellow-green on anything) and a text panel below the centre.
  const glm::vec3 reticle(1.0f, 0.95f, 0.3f);
  std::vector<DrawQuad> quads;
  quads.push_back(headQuad(glm::vec2(0.0f), glm::vec2(12.0f, 1.5f), distance, 0, reticle));
  quads.push_back(headQuad(glm::vec2(0.0f), glm::vec2(1.5f, 12.0f), distance, 0, reticle));
  // The panel: skimage's `text` page (448 x 172 px, aspect 2.6), 44 x 17 px, 23 px below the centre.
  quads.push_back(headQuad(glm::vec2(0.0f, -23.0f), glm::vec2(44.0f, 17.0f), distance, textures.find("text"),
                           glm::vec3(1.0f)));
  return quads;
}

DrawList Scene::drawsAt(double tSec, const HeadPose& head) const {
  DrawList d = draws(tSec);
  if (headLocked.empty()) return d;
  const glm::mat4 toWorld = headToWorld(head);
  for (DrawQuad q : headLocked) {
    q.model = toWorld * q.model;
    d.quads.push_back(q);
  }
  return d;
}

std::vector<uint8_t> overlayMask(const DepthMap& depth, const EyeCamera& cam, float splitDistanceM,
                                 bool dilate) {
  const int w = depth.width, h = depth.height;
  std::vector<uint8_t> near(size_t(w) * h, 0), mask(size_t(w) * h, 0);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const float d = depth.at(x, y);
      if (d >= 1.0f) continue;  // nothing drawn
      const glm::vec3 world = unproject(cam, float(x) + 0.5f, float(y) + 0.5f, d);
      const float viewZ = -(cam.view * glm::vec4(world, 1.0f)).z;
      near[size_t(y) * w + x] = viewZ < splitDistanceM ? 1 : 0;
    }
  }
  if (!dilate) return near;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      bool any = false;
      for (int dy = -1; dy <= 1 && !any; ++dy)
        for (int dx = -1; dx <= 1 && !any; ++dx) {
          const int xx = x + dx, yy = y + dy;
          any = xx >= 0 && yy >= 0 && xx < w && yy < h && near[size_t(yy) * w + xx];
        }
      mask[size_t(y) * w + x] = any ? 1 : 0;
    }
  }
  return mask;
}

double maskedRmse(const Image& a, const Image& b, const std::vector<uint8_t>& mask) {
  double sum = 0;
  size_t n = 0;
  for (size_t i = 0; i < mask.size() && i * 3 + 2 < a.rgb.size() && i * 3 + 2 < b.rgb.size(); ++i) {
    if (!mask[i]) continue;
    for (int c = 0; c < 3; ++c) {
      const double e = double(a.rgb[i * 3 + c]) - double(b.rgb[i * 3 + c]);
      sum += e * e;
    }
    n += 3;
  }
  return n == 0 ? -1.0 : std::sqrt(sum / double(n));
}

OverlayMasks overlayMasks(const std::array<const DepthMap*, 2>& depth, const std::array<EyeCamera, 2>& cams,
                          double fovTangentScale) {
  // Halfway-ish between the HUD (1 m) and the picture (1.5 m).
  const float split = float(1.25 * kHudDistanceM / fovTangentScale);
  OverlayMasks m;
  for (int eye = 0; eye < 2; ++eye) {
    m.all[eye] = overlayMask(*depth[eye], cams[eye], split);
    m.core[eye] = overlayMask(*depth[eye], cams[eye], split, false);
    m.border[eye] = m.all[eye];
    for (size_t i = 0; i < m.border[eye].size(); ++i) m.border[eye][i] &= uint8_t(!m.core[eye][i]);
  }
  return m;
}

double pooledMaskedRmse(const std::array<Image, 2>& a, const std::array<Image, 2>& b,
                        const std::array<std::vector<uint8_t>, 2>& mask, double* pixels) {
  double sq = 0, n = 0;
  for (int eye = 0; eye < 2; ++eye) {
    const double r = maskedRmse(a[eye], b[eye], mask[eye]);
    const double px = double(std::count(mask[eye].begin(), mask[eye].end(), uint8_t(1)));
    if (r >= 0) sq += r * r * px, n += px;
  }
  if (pixels) *pixels = n;
  return n > 0 ? std::sqrt(sq / n) : -1.0;
}

std::string overlayCsvRow(const std::array<Image, 2>& out, const std::array<Image, 2>& truth,
                          const OverlayMasks& masks) {
  double n = 0;
  const double all = pooledMaskedRmse(out, truth, masks.all, &n);
  return fmt(all, 6) + ',' + std::to_string(int(n)) + ',' +
         fmt(pooledMaskedRmse(out, truth, masks.core, nullptr), 6) + ',' +
         fmt(pooledMaskedRmse(out, truth, masks.border, nullptr), 6);
}

}  // namespace steadyxr::eval
