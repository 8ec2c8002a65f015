// Independent CPU implementations of the filter passes, written from the equations (seed 001,
// 002, 003) with the view_math projection (unit tested separately), not from the filter core
// (layer/core/src/filter_*).
#pragma once

#include "gpu_image.h"
#include "steadyxr/core/params.h"

namespace steadyxr::test {

struct RefView {
  core::Pose pose;
  core::Fov fov;
};

// Pixel centre pc of `from` at view distance `dist` (metres) -> continuous pixel coords in `to`.
bool reprojectRef(glm::vec2 pc, float dist, const RefView& from, const RefView& to, glm::uvec2 size,
                  glm::vec2* q, float* distTo);
// The same where the two views' images differ in size (an app's dynamic resolution): pc in fromSize's
// pixels, q in toSize's.
bool reprojectRef(glm::vec2 pc, float dist, const RefView& from, glm::uvec2 fromSize, const RefView& to,
                  glm::uvec2 toSize, glm::vec2* q, float* distTo);

glm::vec3 fetchClamped(const HostImage& img, int x, int y);
glm::vec3 bilinear(const HostImage& img, glm::vec2 q);
// Catmull-Rom at q without its four corner texels (renormalised), clamped at 0.
glm::vec3 catmullRom5(const HostImage& img, glm::vec2 q);

// One temporal step. `hist` is the previous history (any size: the app's last render size), `histValid` false
// on the first frame. headSpeed in deg/s. Returns the new history (= the output when no stereo follows).
HostImage temporalRef(core::TemporalMethod m, const core::Params& p, const HostImage& cur,
                      const HostImage& hist, bool histValid, const RefView& prev, const RefView& now,
                      float headSpeed, const HostImage* depth = nullptr, float nearZ = 0.1f,
                      float farZ = 100.0f);

// One step of the steady method (steady_reference.cpp). The history's alpha holds its sample
// count; so does the returned image's. jitterPx: `cur` was rendered on a grid shifted by it
// (ViewFrame::jitterPx: its pixel c holds the point at c + jitterPx of the output grid).
// srgbInput: `cur` came from an 8-bit sRGB image (Params::steadyClipQuantSrgb's floor applies).
HostImage steadyRef(const core::Params& p, const HostImage& cur, const HostImage& hist, bool histValid,
                    const RefView& prev, const RefView& now, const HostImage* depth = nullptr,
                    float nearZ = 0.1f, float farZ = 100.0f, glm::vec2 jitterPx = glm::vec2(0.0f),
                    bool srgbInput = false);

HostImage fxaaRef(const HostImage& in);

// Stereo blend of eye `thisEye` with `other` (seed 002 §4.1). Depths optional (D32 values in .r).
HostImage stereoRef(const core::Params& p, const HostImage& thisEye, const HostImage& other,
                    const RefView& thisView, const RefView& otherView, const HostImage* thisDepth,
                    const HostImage* otherDepth, float nearZ, float farZ, bool inverseVariance = false);

// The general stereo blend: this eye's values `self`, its 3x3 statistics from `stats` (in YCoCg
// when yCoCgStats), the other eye's image `other` sampled where this pixel lands in
// otherSampleView, the depth check where it lands in otherDepthView. stereoRef is the case
// self = stats, both other views the same.
HostImage stereoBlendRef(const core::Params& p, const HostImage& self, const HostImage& stats,
                         bool yCoCgStats, const HostImage& other, const RefView& selfView,
                         const RefView& otherSampleView, const RefView& otherDepthView,
                         const HostImage* selfDepth, const HostImage* otherDepth, float nearZ, float farZ,
                         bool inverseVariance = false);
// inverseVariance (after steady, Params::stereoInverseVariance): beta from the two estimates'
// error variances, each eye's sample count in its image's alpha, in place of Eq. 4.

}  // namespace steadyxr::test
