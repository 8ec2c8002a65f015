// The evaluation scenes: each is a handful of textured quads, a function of time (for moving
// objects), an optional head translation it adds (disocclusion), and the per-pixel motion field
// that seed 004's forward warp needs.
#pragma once

#include "eye_rig.h"
#include "image.h"
#include "renderer.h"
#include "warp.h"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

namespace steadyxr::eval {

// Textures every scene can use, uploaded once. Index 0 is plain white (flat-coloured quads).
struct TextureSet {
  std::vector<Rgba8> images;
  std::vector<std::string> names;
  uint32_t find(const std::string& name) const;  // 0 when absent
};

// Loads `nameOrPath`: an existing PNG file, or NAME.png in `picturesDir` (python3-skimage's data
// by default). False with *error in the user's words (what was looked for, and a file of the same
// name in another format) when neither loads.
bool loadPicture(const std::string& nameOrPath, const std::string& picturesDir, Rgba8* out,
                 std::string* error);
// loadPicture, else a procedural checkerboard with a note in *warning: only for the pictures the
// scenes load on their own (a video's second picture), never for one the user named, whose figures
// would then be the checkerboard's.
Rgba8 loadTextureOrFallback(const std::string& nameOrPath, const std::string& picturesDir,
                            std::string* warning);
inline constexpr const char* kDefaultPicturesDir = "/usr/lib/python3/dist-packages/skimage/data";
std::string textureKey(const std::string& nameOrPath);  // file stem

struct Scene {
  std::string name;     // "imageviewer", "thin", "moving", "disocclusion", "noisy", "hud", "video", "fade",
                        // "blink"
  std::string picture;  // texture key of the picture (image-viewer scenes)
  bool hasMovingObject = false;
  DrawList drawsAt(double tSec) const;  // the world-locked draws alone
  // The frame's draws with head-locked content (`hud`, scene_hud.h) at the render pose `head`.
  DrawList drawsAt(double tSec, const HeadPose& head) const;
  glm::vec3 headOffset(double tSec) const;  // extra head translation (metres, world)
  // Seed 004's V = P_n - P_{n-1}: motion of the surface point p (seen at time t) over dt.
  glm::vec3 motion(const glm::vec3& p, double tSec, double dtSec) const;
  // Speed of the moving object (m/s) at t, 0 for static scenes.
  float objectSpeed(double tSec) const;

  std::function<DrawList(double)> draws;
  std::function<glm::vec3(double)> offset;
  std::function<glm::mat4(double)> movingModel;  // model matrix of the moving quad, if any
  std::vector<DrawQuad> headLocked;              // quads in head space (scene_hud.h); empty: none
  // Content scenes (video, fade, blink): the times in [t0, t1] where the content changes in place
  // (a cut, a fade's start or end, a flash, a light switching); empty for the others.
  std::function<std::vector<double>(double, double)> contentChanges;
};

// Scenes whose content changes over time on the image viewer's screen (scene_video.cpp):
// "video" (24 fps content, a Ken Burns zoom and a fast pan, a cut every 0.5 s to another picture),
// "fade" (the whole view's light fades down and up, then a flash), "blink" (a small light at 2 Hz).
bool isContentScene(const std::string& name);
// The scenes built on the image viewer, which show the `--images` picture: imageviewer, noisy, hud
// and the content scenes (the others have their own geometry and textures).
bool isPictureScene(const std::string& name);
// The video's content rate and its content frame at app time t: the draws change only between frames.
inline constexpr double kVideoContentHz = 24.0;
int64_t videoContentFrame(double tSec);
// Fills s->draws and s->contentChanges of content scene `name` around the image viewer's `plane`
// (picture `picture`, at distanceScale times its 1.5 m).
void makeContentScene(const std::string& name, const TextureSet& t, uint32_t picture, const DrawQuad& plane,
                      float distanceScale, Scene* s);

const std::vector<std::string>& sceneNames();
// `picture` is used by the picture scenes (isPictureScene); textures must hold it.
// fovTangentScale: --ppd's narrowing of the eye fov (eye_rig.h, ppdTangentScale; 1 = off). The
// image viewer moves its picture 1/fovTangentScale times further away, so the picture covers the
// same pixels as without --ppd; the other scenes (thin, moving, disocclusion) are stretched in depth
// about `ppdStartHead` (the first frame's head pose) by ppdDepthStretch (eye_rig.h), so that from
// it every frame is the picture it is without --ppd; refused (false, *error) where the stretched
// scene would reach beyond 90 % of the far plane.
bool makeScene(const std::string& name, const std::string& picture, const TextureSet& textures,
               double fovTangentScale, const HeadPose& ppdStartHead, Scene* out, std::string* error);

}  // namespace steadyxr::eval
