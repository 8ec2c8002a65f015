// Scenes whose content changes in place (issue 14, round 7): a video on the image viewer's
// screen, a lighting fade with a flash, a blinking light. A layer sees no motion vectors and no
// app state, so to it these are changes the head did not cause; TAA-like filters are known to lag
// on them (the history is clipped to the current 3x3's box, and a change inside the box is kept).
#include "scene.h"

#include <cmath>
#include <utility>

#include <glm/gtc/matrix_transform.hpp>

namespace steadyxr::eval {

namespace {

// Video: shots of kVideoShotSec (a cut between them, to the other picture), content frames at
// kVideoContentHz. 0.5 s shots, shorter than a film's ~1-3 s, so that the short stress runs
// (eval/stress.py: 24 frames at 90 Hz is 0.27 s, at 30 Hz 0.8 s) and the corpus's 48 frames at
// 90 Hz (0.53 s) hold a cut; even shots zoom in slowly on the picture, odd shots pan fast over the
// other one.
constexpr double kVideoShotSec = 0.5;
// Pan per content frame in picture widths. The image viewer's picture is 1.2 m tall at 1.5 m, 39 px
// at the corpus's 96 px (focal 48.7 px: 0.85 px/deg) and as many under --ppd (the picture moves
// away, scene.cpp): 0.008 widths is 0.3 px a content frame on a square picture (sub-pixel), 0.08 is
// 3.1 px (several pixels); at 256 px 0.8 and 8.3 px.
constexpr double kSlowPanWidthsPerFrame = 0.008;
constexpr double kFastPanWidthsPerFrame = 0.08;
// Ken Burns zoom of the slow shots: the shown part of the picture shrinks from 1 to 0.8 over the
// shot (its edges move by 0.1 / 0.8 * 39 / 12, ~0.4 px a content frame at 96 px).
constexpr double kSlowZoomEnd = 0.8;
// The fast shots show 0.6 of the picture (a close-up), panning right.
constexpr double kFastShotScale = 0.6;

// Fade: period 2 s. Full light, a 0.6 s fade down to 15 % (a dimmed cinema, not black: the
// filters' boxes still see texture), held, a 0.5 s fade back up, then a 50 ms flash at 1.8x
// (saturates highlights in the 8-bit eye image, as a real flash does).
struct FadeKey {
  double tSec;
  double tint;
};
constexpr double kFadePeriodSec = 2.0;
constexpr double kFadeLow = 0.15;
constexpr double kFlashTint = 1.8;
constexpr FadeKey kFadeKeys[] = {{0.0, 1.0},  {0.2, 1.0}, {0.8, kFadeLow},   {1.0, kFadeLow},
                                 {1.5, 1.0},  {1.7, 1.0}, {1.7, kFlashTint}, {1.75, kFlashTint},
                                 {1.75, 1.0}, {2.0, 1.0}};

// Blink: a warm light on the picture, on for 0.25 s, off for 0.25 s (2 Hz), 8 cm wide (3 px at
// 96 px: a small UI element or indicator light).
constexpr double kBlinkHalfPeriodSec = 0.25;
constexpr float kBlinkSizeM = 0.08f;

int64_t floorIndex(double tSec, double periodSec) {
  // 1e-9: an app time a rounding below a content instant still shows that instant's frame.
  return int64_t(std::floor(tSec / periodSec + 1e-9));
}

double fadeTint(double tSec) {
  const double local = tSec - kFadePeriodSec * std::floor(tSec / kFadePeriodSec);
  for (size_t i = 1; i < std::size(kFadeKeys); ++i) {
    const FadeKey &a = kFadeKeys[i - 1], &b = kFadeKeys[i];
    if (local < b.tSec) {
      const double span = b.tSec - a.tSec;
      return span > 0.0 ? a.tint + (b.tint - a.tint) * (local - a.tSec) / span : b.tint;
    }
  }
  return kFadeKeys[std::size(kFadeKeys) - 1].tint;
}

// The times in [t0, t1] where the content starts or stops changing: a key of the fade (periodic),
// a multiple of `step` otherwise.
std::vector<double> stepsIn(double t0, double t1, double step) {
  std::vector<double> out;
  for (int64_t k = int64_t(std::ceil(t0 / step - 1e-9)); double(k) * step <= t1 + 1e-9; ++k)
    out.push_back(double(k) * step);
  return out;
}
std::vector<double> fadeKeysIn(double t0, double t1) {
  std::vector<double> out;
  for (int64_t p = int64_t(std::floor(t0 / kFadePeriodSec)); double(p) * kFadePeriodSec <= t1; ++p) {
    for (size_t i = 1; i + 1 < std::size(kFadeKeys); ++i) {
      const double t = double(p) * kFadePeriodSec + kFadeKeys[i].tSec;
      if (t >= t0 - 1e-9 && t <= t1 + 1e-9 && (out.empty() || out.back() != t)) out.push_back(t);
    }
  }
  return out;
}

}  // namespace

bool isContentScene(const std::string& name) {
  return name == "video" || name == "fade" || name == "blink";
}

int64_t videoContentFrame(double tSec) {
  return floorIndex(tSec, 1.0 / kVideoContentHz);
}

void makeContentScene(const std::string& name, const TextureSet& t, uint32_t picture, const DrawQuad& plane,
                      float distanceScale, Scene* s) {
  const glm::vec3 clear(0.15f);  // the image viewer's background
  if (name == "video") {
    // The cut's other picture: one the eval always loads (scenario_list.cpp, gatherTextures).
    const uint32_t other =
        t.find("coffee") != picture && t.find("coffee") ? t.find("coffee") : t.find("camera");
    s->draws = [plane, picture, other, clear](double tt) {
      const int64_t frame = videoContentFrame(tt);  // what the screen shows is fixed within a frame
      const int64_t perShot = int64_t(std::llround(kVideoShotSec * kVideoContentHz));
      const int64_t shot = frame >= 0 ? frame / perShot : (frame - perShot + 1) / perShot;
      const double i = double(frame - shot * perShot);  // content frame within the shot
      DrawQuad q = plane;
      if (shot % 2 == 0) {
        q.texture = picture;
        const double scale = 1.0 - (1.0 - kSlowZoomEnd) * i / double(perShot);
        const double centreOffset = 0.5 * (1.0 - scale);
        q.uvST = glm::vec4(float(scale), float(scale),
                           float(centreOffset + kSlowPanWidthsPerFrame * i * scale), float(centreOffset));
      } else {
        q.texture = other;
        const double scale = kFastShotScale;
        // The sampler repeats (renderer_textures.cpp): the pan wraps once per shot, a moving seam.
        q.uvST = glm::vec4(float(scale), float(scale), float(0.2 + kFastPanWidthsPerFrame * i * scale), 0.2f);
      }
      DrawList d;
      d.clearColor = clear;
      d.quads = {q};
      return d;
    };
    s->contentChanges = [](double t0, double t1) { return stepsIn(t0, t1, kVideoShotSec); };
  } else if (name == "fade") {
    // A lighting change of the whole view: the picture and the background dim together.
    s->draws = [plane, clear](double tt) {
      const float k = float(fadeTint(tt));
      DrawQuad q = plane;
      q.tint = glm::vec4(glm::vec3(k), 1.0f);
      DrawList d;
      d.clearColor = clear * k;
      d.quads = {q};
      return d;
    };
    s->contentChanges = fadeKeysIn;
  } else {  // blink
    // On the picture, up and right of its centre, 2 mm in front of it (scaled with --ppd's distance).
    const glm::vec3 centre = glm::vec3(plane.model[3]) + distanceScale * glm::vec3(0.25f, 0.2f, 0.002f);
    DrawQuad light = plane;
    light.model = glm::scale(glm::translate(glm::mat4(1.0f), centre),
                             glm::vec3(distanceScale * kBlinkSizeM, distanceScale * kBlinkSizeM, 1.0f));
    light.texture = 0;  // plain white
    light.tint = glm::vec4(1.0f, 0.85f, 0.5f, 1.0f);
    light.uvST = glm::vec4(1.0f, 1.0f, 0.0f, 0.0f);
    s->draws = [plane, light, clear](double tt) {
      DrawList d;
      d.clearColor = clear;
      d.quads = {plane};
      if (floorIndex(tt, kBlinkHalfPeriodSec) % 2 != 0) d.quads.push_back(light);
      return d;
    };
    s->contentChanges = [](double t0, double t1) { return stepsIn(t0, t1, kBlinkHalfPeriodSec); };
  }
}

}  // namespace steadyxr::eval
