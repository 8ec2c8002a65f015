#include "scene.h"

#include "scene_hud.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>

namespace steadyxr::eval {

namespace {

glm::mat4 quadModel(glm::vec3 centre, glm::vec2 size, float rollRad = 0.0f) {
  glm::mat4 m = glm::translate(glm::mat4(1.0f), centre);
  m = glm::rotate(m, rollRad, glm::vec3(0.0f, 0.0f, 1.0f));
  return glm::scale(m, glm::vec3(size, 1.0f));
}

DrawQuad quad(glm::mat4 model, uint32_t texture, glm::vec3 tint = glm::vec3(1.0f),
              glm::vec4 uvST = glm::vec4(1.0f, 1.0f, 0.0f, 0.0f)) {
  DrawQuad q;
  q.model = model;
  q.texture = texture;
  q.tint = glm::vec4(tint, 1.0f);
  q.uvST = uvST;
  return q;
}

// Picture plane 1.5 m ahead, fitted into 1.6 m x 1.2 m keeping the image's aspect ratio. Under
// --ppd it is `distanceScale` times further: a fronto-parallel plane's image scales with
// focal length / distance, so the picture keeps its pixels while head rotation moves it by the
// headset's pixels per degree (and the eyes' disparity and head translation by what they would
// at that distance).
DrawQuad picturePlane(const TextureSet& t, uint32_t tex, float distanceScale) {
  const Rgba8& img = t.images[tex];
  const float aspect = img.height > 0 ? float(img.width) / float(img.height) : 1.0f;
  glm::vec2 size(1.2f * aspect, 1.2f);
  if (size.x > 1.6f) size *= 1.6f / size.x;
  return quad(quadModel(glm::vec3(0.0f, 0.0f, -1.5f * distanceScale), size), tex);
}

}  // namespace

uint32_t TextureSet::find(const std::string& name) const {
  for (size_t i = 0; i < names.size(); ++i) {
    if (names[i] == name) return uint32_t(i);
  }
  return 0;
}

std::string textureKey(const std::string& nameOrPath) {
  return std::filesystem::path(nameOrPath).stem().string();
}

bool loadPicture(const std::string& nameOrPath, const std::string& picturesDir, Rgba8* out,
                 std::string* error) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const std::string inPicturesDir = picturesDir + "/" + nameOrPath + ".png";
  std::string unreadable;  // the first candidate that exists but does not read as PNG
  for (const std::string& path : {nameOrPath, inPicturesDir}) {
    if (!fs::is_regular_file(path, ec)) continue;
    std::string err;
    if (loadPng(path, out, &err)) return true;
    if (unreadable.empty()) unreadable = path + " is not a PNG steadyxr-eval can read (" + err + ")";
  }
  if (!unreadable.empty()) {
    *error = "picture '" + nameOrPath + "': " + unreadable;
    return false;
  }
  *error = "picture '" + nameOrPath + "' not found: no file '" + nameOrPath + "' and no " + inPicturesDir;
  // A picture in another format (python3-skimage ships some as JPEG): say so, since only PNG is read.
  const fs::path dir =
      fs::path(nameOrPath).has_parent_path() ? fs::path(nameOrPath).parent_path() : fs::path(picturesDir);
  const std::string stem = textureKey(nameOrPath);
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    if (it->path().stem() == stem && it->is_regular_file(ec)) {
      *error += "; " + it->path().string() +
                " is there, but steadyxr-eval reads PNG only: convert it to PNG and give the PNG's path";
      break;
    }
  }
  return false;
}

Rgba8 loadTextureOrFallback(const std::string& nameOrPath, const std::string& picturesDir,
                            std::string* warning) {
  Rgba8 img;
  std::string err;
  if (loadPicture(nameOrPath, picturesDir, &img, &err)) return img;
  if (warning) *warning = err + "; using a checkerboard";
  img.width = img.height = 256;
  img.pixels.resize(256 * 256 * 4);
  for (int y = 0; y < 256; ++y) {
    for (int x = 0; x < 256; ++x) {
      const uint8_t v = ((x / 8 + y / 8) % 2) ? 230 : 25;
      uint8_t* p = &img.pixels[(size_t(y) * 256 + x) * 4];
      p[0] = p[1] = p[2] = v;
      p[3] = 255;
    }
  }
  return img;
}

const std::vector<std::string>& sceneNames() {
  static const std::vector<std::string> names = {"imageviewer", "thin",  "moving", "disocclusion", "noisy",
                                                 "hud",         "video", "fade",   "blink"};
  return names;
}

bool isPictureScene(const std::string& name) {
  return name == "imageviewer" || name == "noisy" || name == "hud" || isContentScene(name);
}

DrawList Scene::drawsAt(double tSec) const {
  return draws(tSec);
}
glm::vec3 Scene::headOffset(double tSec) const {
  return offset ? offset(tSec) : glm::vec3(0.0f);
}

glm::vec3 Scene::motion(const glm::vec3& p, double tSec, double dtSec) const {
  if (!movingModel) return glm::vec3(0.0f);
  const glm::mat4 now = movingModel(tSec);
  const glm::vec4 local = glm::inverse(now) * glm::vec4(p, 1.0f);
  // On the moving quad? (its local z is in world metres: the model does not scale z; under --ppd
  // the depth stretch scales it with the scene's depths)
  if (std::fabs(local.z) > 0.01f || std::fabs(local.x) > 0.52f || std::fabs(local.y) > 0.52f) {
    return glm::vec3(0.0f);
  }
  const glm::vec3 before = glm::vec3(movingModel(tSec - dtSec) * local);
  return p - before;
}

float Scene::objectSpeed(double tSec) const {
  if (!movingModel) return 0.0f;
  constexpr double h = 1e-3;
  const glm::vec3 a = glm::vec3(movingModel(tSec - h)[3]), b = glm::vec3(movingModel(tSec + h)[3]);
  return float(glm::length(b - a) / (2.0 * h));
}

bool makeScene(const std::string& name, const std::string& picture, const TextureSet& t,
               double fovTangentScale, const HeadPose& ppdStartHead, Scene* out, std::string* error) {
  const bool imageViewer = isPictureScene(name);
  // --ppd for the scenes in metres: every model matrix goes through the depth stretch. Off (scale
  // 1) the matrices are used as they are, so every result without --ppd stays bit-identical.
  const bool stretched = fovTangentScale != 1.0 && !imageViewer;
  const glm::mat4 stretch = stretched ? ppdDepthStretch(ppdStartHead, fovTangentScale) : glm::mat4(1.0f);
  auto place = [stretched, stretch](glm::mat4 model) { return stretched ? stretch * model : model; };
  const glm::vec3 forward = ppdStartHead.orientation * glm::vec3(0.0f, 0.0f, -1.0f);
  float farthestM = 0.0f;  // the stretched scene's depth from the start eye (far plane check)
  auto reach = [&](const glm::mat4& model) {
    for (const glm::vec2 corner :
         {glm::vec2(-0.5f), glm::vec2(0.5f), glm::vec2(-0.5f, 0.5f), glm::vec2(0.5f, -0.5f)})
      farthestM = std::max(
          farthestM,
          glm::dot(glm::vec3(model * glm::vec4(corner, 0.0f, 1.0f)) - ppdStartHead.position, forward));
  };
  Scene s;
  s.name = name;
  const uint32_t pic = t.find(textureKey(picture));
  if (imageViewer) {
    // Seed 003's own experiment: a picture on a plane in front of the user.
    s.picture = textureKey(picture);
    const DrawQuad plane = picturePlane(t, pic, float(1.0 / fovTangentScale));
    if (isContentScene(name)) makeContentScene(name, t, pic, plane, float(1.0 / fovTangentScale), &s);
    const float noise = name == "noisy" ? 0.08f : 0.0f;
    if (!s.draws)
      s.draws = [plane, noise](double) {
        DrawList d;
        d.clearColor = glm::vec3(0.15f);
        d.quads = {plane};
        d.noiseAmplitude = noise;
        return d;
      };
    if (name == "hud") s.headLocked = hudOverlay(t, fovTangentScale);  // head-locked, in front
  } else if (name == "thin") {
    // A wire fence 3 m away (posts 3 cm, wires 6 mm: below a pixel) before a page of text at 5 m.
    const uint32_t text = t.find("text");
    std::vector<DrawQuad> quads;
    quads.push_back(quad(quadModel(glm::vec3(0.0f, 0.2f, -5.0f), glm::vec2(2.6f, 1.04f)), text));
    for (int i = 0; i < 9; ++i) {
      quads.push_back(quad(quadModel(glm::vec3(-2.0f + 0.5f * i, -0.3f, -3.0f), glm::vec2(0.03f, 1.6f)), 0,
                           glm::vec3(0.35f, 0.25f, 0.15f)));
    }
    for (int i = 0; i < 6; ++i) {
      quads.push_back(quad(quadModel(glm::vec3(0.0f, -0.9f + 0.25f * i, -2.99f), glm::vec2(4.6f, 0.006f)), 0,
                           glm::vec3(0.08f)));
    }
    for (int i = 0; i < 2; ++i) {
      quads.push_back(
          quad(quadModel(glm::vec3(0.0f, -0.3f, -2.98f), glm::vec2(4.6f, 0.006f), i ? 0.3f : -0.3f), 0,
               glm::vec3(0.08f)));
    }
    for (DrawQuad& q : quads) q.model = place(q.model);
    s.draws = [quads](double) {
      DrawList d;
      d.clearColor = glm::vec3(0.55f, 0.7f, 0.9f);
      d.quads = quads;
      return d;
    };
  } else if (name == "moving") {
    // A picture sliding sideways (peak ~1.3 m/s, ~50 deg/s) over a brick wall.
    const uint32_t brick = t.find("brick");
    const uint32_t obj = t.find("coffee") ? t.find("coffee") : pic;
    s.hasMovingObject = true;
    // Stretched as a whole: its path's lateral metres (and so its pixels per frame) are kept.
    s.movingModel = [place](double tt) {
      const float x = 0.5f * float(std::sin(2.0 * std::numbers::pi * 0.4 * tt));
      return place(quadModel(glm::vec3(x, 0.0f, -1.5f), glm::vec2(0.6f, 0.4f)));
    };
    const DrawQuad wall = quad(place(quadModel(glm::vec3(0.0f, 0.0f, -2.5f), glm::vec2(5.0f, 4.0f))), brick,
                               glm::vec3(1.0f), glm::vec4(3.0f, 3.0f, 0.0f, 0.0f));
    reach(wall.model);
    reach(s.movingModel(0.0));
    auto model = s.movingModel;
    s.draws = [wall, obj, model](double tt) {
      DrawList d;
      d.clearColor = glm::vec3(0.15f);
      d.quads = {wall, quad(model(tt), obj)};
      return d;
    };
  } else if (name == "disocclusion") {
    // Near posts and a mid-distance panel before a far grass wall; the head sways sideways (a
    // lateral translation: under --ppd's depth stretch it moves the pixels it moves without).
    const uint32_t grass = t.find("grass"), brick = t.find("brick"), camera = t.find("camera");
    std::vector<DrawQuad> quads;
    quads.push_back(quad(quadModel(glm::vec3(0.0f, 0.0f, -5.0f), glm::vec2(9.0f, 7.0f)), grass,
                         glm::vec3(1.0f), glm::vec4(2.0f, 2.0f, 0.0f, 0.0f)));
    quads.push_back(quad(quadModel(glm::vec3(0.5f, 0.1f, -2.5f), glm::vec2(1.0f, 1.0f)), camera));
    for (int i = 0; i < 3; ++i) {
      quads.push_back(quad(quadModel(glm::vec3(-0.6f + 0.6f * i, -0.2f, -1.2f), glm::vec2(0.2f, 2.0f)), brick,
                           glm::vec3(1.0f), glm::vec4(0.2f, 1.0f, 0.0f, 0.0f)));
    }
    for (DrawQuad& q : quads) q.model = place(q.model);
    s.draws = [quads](double) {
      DrawList d;
      d.clearColor = glm::vec3(0.5f);
      d.quads = quads;
      return d;
    };
    s.offset = [](double tt) {
      return glm::vec3(0.1f * float(std::sin(2.0 * std::numbers::pi * 0.5 * tt)), 0.0f, 0.0f);
    };
  } else {
    if (error) *error = "unknown scene '" + name + "'";
    return false;
  }
  if (s.draws && !s.movingModel)
    for (const DrawQuad& q : s.draws(0.0).quads) reach(q.model);
  if (stretched && farthestM > 0.9f * kFarZ) {
    if (error)
      *error = "scene '" + name + "' stretched for --ppd reaches " + std::to_string(int(farthestM)) +
               " m, beyond 90 % of the far plane (" + std::to_string(int(kFarZ)) +
               " m): fewer ppd or more pixels";
    return false;
  }
  *out = std::move(s);
  return true;
}

}  // namespace steadyxr::eval
