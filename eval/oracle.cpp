#include "oracle.h"

#include <glm/glm.hpp>

#include <cmath>
#include <vector>

namespace steadyxr::eval {

namespace {

// A sample is still visible when its distance from the current eye agrees with the current depth's
// to 2 % (the stereo metric's tolerance, metrics.h).
constexpr float kRelativeDepthTolerance = 0.02f;

}  // namespace

void Oracle::reset() {
  for (auto& f : frames_) f.clear();
}

Image Oracle::step(int eye, const Image& rendered, const DepthMap& renderedDepth, const EyeCamera& renderCam,
                   const DepthMap& outDepth, const EyeCamera& outCam) {
  std::deque<Frame>& frames = frames_[eye];
  Frame f{rendered, renderedDepth, renderCam};
  if (linear_) {
    for (float& v : f.color.rgb) v = srgbToLinear(v);
  }
  frames.push_front(std::move(f));
  if (frames.size() > kWindow) frames.pop_back();

  const int w = outDepth.width, h = outDepth.height;
  std::vector<double> sum(size_t(w) * h * 3, 0.0);
  std::vector<int> count(size_t(w) * h, 0);
  for (const Frame& fr : frames) {
    // Visibility only changes when the eye moved (a translation of over 1 mm).
    const bool translated = glm::length(fr.cam.pose.position - outCam.pose.position) > 1e-3f;
    for (int sy = 0; sy < fr.color.height; ++sy) {
      for (int sx = 0; sx < fr.color.width; ++sx) {
        const float d = fr.depth.at(sx, sy);
        const bool background = d >= 1.0f;
        const glm::vec3 p = unproject(fr.cam, sx + 0.5f, sy + 0.5f, background ? 0.999999f : d);
        glm::vec2 u;
        float ud = 0.0f;
        if (!project(outCam, p, &u, &ud)) continue;
        const int x = int(std::floor(u.x)), y = int(std::floor(u.y));
        if (x < 0 || y < 0 || x >= w || y >= h) continue;
        if (translated) {
          const float seenDepth = outDepth.at(x, y);
          if (background != (seenDepth >= 1.0f)) continue;
          if (!background) {
            const glm::vec3 eyePos = outCam.pose.position;
            const glm::vec3 seen = unproject(outCam, x + 0.5f, y + 0.5f, seenDepth);
            const float dp = glm::length(p - eyePos), ds = glm::length(seen - eyePos);
            if (std::fabs(dp - ds) > kRelativeDepthTolerance * dp) continue;
          }
        }
        const float* c = fr.color.at(sx, sy);
        const size_t i = size_t(y) * w + x;
        for (int ch = 0; ch < 3; ++ch) sum[i * 3 + ch] += c[ch];
        ++count[i];
      }
    }
  }
  Image out(w, h);
  const Image& current = frames.front().color;
  for (size_t i = 0; i < count.size(); ++i) {
    for (int ch = 0; ch < 3; ++ch) {
      // No sample inside the pixel (a disocclusion, a gap): the current frame's pixel, as a method would.
      const float v = count[i] > 0 ? float(sum[i * 3 + ch] / count[i]) : current.rgb[i * 3 + ch];
      out.rgb[i * 3 + ch] = linear_ ? linearToSrgb(v) : v;
    }
  }
  return out;
}

}  // namespace steadyxr::eval
