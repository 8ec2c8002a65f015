// One unit per pass on the host side: what it reads and writes, its specialisation key and its
// uniforms (copy, fxaa, temporal, stereo).
#pragma once

#include <array>
#include <cstdint>

#include <vulkan/vulkan.h>

#include "filter_head_locked.h"
#include "filter_pipelines.h"
#include "filter_resources.h"
#include "pass_uniforms.h"
#include "steadyxr/core/frame.h"
#include "steadyxr/core/params.h"

namespace steadyxr::core::detail {

// The temporal pass's kMode (temporal.comp).
constexpr int kModeTaa = 0, kModeHmtaa = 1, kModeVtaa = 2, kModeHybrid = 3, kModeSteady = 4;

// The per-pipeline switches of one dispatch; they become specialisation constants (SpecKey,
// constant_id in common.glsl), not uniforms.
struct PassSwitches {
  int32_t mode = 0;         // temporal: kModeTaa ... kModeSteady
  int32_t sampleCount = 1;  // temporal: past samples (seed 003 Eq. 2)
  bool writeOutput = false;
  bool writeHistory = false;
  bool encodeSrgb = false;
  bool swapRedBlue = false;
  bool inputSrgb = false;       // the app's image is sRGB: the passes read it decoded to linear light
  int32_t depthBits = 0;        // bit0: this eye's depth, bit1: the other eye's
  int32_t historyEncoding = 0;  // kHistoryEncoding: 0 RGBA16F, 1 RGBA8 dithered, 2 RGBA8 nearest
  bool probe =
      false;  // steady: the frame's probe (gain, round 16; noise samples, round 22), no output, no history
};

// Params::steadyOutputHold in force: steady's temporal pass keeps the codes of the 8-bit output it writes.
inline bool outputHeld(const Params& p) {
  return p.temporal == TemporalMethod::Steady && p.steadyOutputHold > 0.0f;
}

// An image a pass samples.
struct Binding {
  VkImageView view = VK_NULL_HANDLE;
  VkImageLayout layout = VK_IMAGE_LAYOUT_GENERAL;
  bool clean = false;  // finite by construction (our history, 8-bit input): the shader skips sanitising
};

// What one dispatch reads and writes, by binding of common.glsl; a null view is a 1x1 dummy.
struct PassIo {
  Binding src0;                             // 0: this eye (input or this frame's history)
  Binding src1;                             // 1: the history (temporal) or the other eye (stereo)
  Binding depth0;                           // 2: this eye's depth
  Binding depth1;                           // 3: the other eye's depth
  VkImageView historyOut = VK_NULL_HANDLE;  // 4 (RGBA16F) or 8 (RGBA8): this frame's history
  VkImageView output = VK_NULL_HANDLE;      // 5: the output (or its scratch image)
  Binding appInput;                         // 7: the app's input of this eye (every output's alpha)
  Binding shownIn;                          // 10: the codes the output showed last frame (hold)
  VkImageView shownOut = VK_NULL_HANDLE;    // 11: the codes it shows this frame
  bool outputIsShown = false;               // 5 is the codes' image (Target::holdsShownCodes); 11 unused
  VkImageView headLockedRecord = VK_NULL_HANDLE;  // 4 in the probe, which writes no history (round 42)
};

// One dispatch, ready to record.
struct PassDispatch {
  Pass pass = Pass::Copy;
  OutFmt fmt = kOut8;
  PassUniforms uniforms{};
  PassSwitches switches;
  PassIo io;
};

// Where an eye's output goes: its storage view, or an intermediate copied to it.
struct Target {
  VkImageView view = VK_NULL_HANDLE;
  OutFmt fmt = kOut8;
  OwnedImage* scratch = nullptr;  // non-null: write here, then vkCmdCopyImage to the output
  bool holdsShownCodes = false;   // scratch is the eye's image of this frame's held codes (stagesHeldOutput)
  bool srgb = false;
  bool swap = false;
  // The held codes it writes are in BGRA order (staged for a BGRA image: EyeState::shownBgra).
  bool codesBgra() const { return holdsShownCodes && swap; }
};

// What submit decided about this frame before recording: the passes to run, and per eye its
// checked inputs and bound images.
struct FramePlan {
  uint32_t viewCount = 0;
  bool temporal = false;    // a temporal method runs in the first stage
  bool fxaa = false;        // fxaa runs in the first stage
  bool stereo = false;      // the stereo pass follows
  bool firstStage = false;  // copy, fxaa or temporal runs (`none` + stereo reads the inputs directly)
  std::array<bool, 2> hasDepth{false, false};
  std::array<bool, 2> poseOk{false, false};
  bool imagesReallocated = false;  // prepareEyes made an eye's internal images anew (not the first time)
  std::array<HeadLockedEyeStep, 2> headLocked{};  // the head-locked switch's step in each eye's probe
  std::array<Target, 2> targets{};
  std::array<Binding, 2> inputs{}, depths{};
};

// What the pass units read: the frame, its plan, the eyes' history and which image is written.
struct PassContext {
  const StereoFrame& frame;
  const StereoOutput& output;
  const Params& params;
  const FramePlan& plan;
  const std::array<EyeState, 2>& eyes;
  uint32_t historyWrite;  // eyes[e].history[historyWrite] is written this frame, the other read
  uint32_t ditherSeed;    // the 8-bit history's dither, new every frame (common.glsl storeHistory)
  float noiseVariance;    // steady: the render's noise variance per linear RGB channel (estimated or told)
  float frameDetailVariance;  // steady: the newest frame's own finest detail, as a variance (round 42), or 0
};

// The first stage of eye e: the app's input through copy, fxaa or a temporal method into this
// frame's history (when stereo follows or the method is temporal) and the output (unless stereo
// follows).
PassDispatch copyPass(const PassContext& c, uint32_t e);
PassDispatch fxaaPass(const PassContext& c, uint32_t e);
PassDispatch temporalPass(const PassContext& c, uint32_t e);
// The temporal pass writes eye e's 8-bit output with steadyOutputHold (and the codes it shows).
bool writesHeldOutput(const PassContext& c, uint32_t e);
// The same, before the pass's context exists (bindTargets): plan.targets[e].fmt is set.
bool writesHeldOutput(const Params& params, const FramePlan& plan, const EyeState& eye, uint32_t e);
// Steady's probe of eye e: before the temporal passes, both eyes. It samples the frame's gain
// (Params::steadyGainCompensation) and the render's noise (Params::steadyNoiseEstimate) into the records.
PassDispatch probePass(const PassContext& c, uint32_t e);
// The probe's samples: the pixels at (B/2 + i B, B/2 + j B) of an eye of width x height, for blocks of
// side B. Their count, and the side the probe takes: the smallest from 4 px (one pixel in 16) up whose
// blocks hold at most kProbeSamplesPerEye samples. Round 28: 1024, the samples every evaluated eye
// (96-128 px: the corpus, every held-out draw) measured its noise and its fades with. Round 17's 16384
// tightened the fade test beyond anything tested, and under it one pixel in 16 (4096 samples an eye at
// 256x256) took the default over the cost limit. The probe's cost stops growing with the
// resolution. One invocation per block (round 22).
constexpr int32_t kProbeSmallestBlockPx = 4;
constexpr int64_t kProbeSamplesPerEye = 1024;
int64_t probeSamples(int32_t width, int32_t height, int32_t blockPx);
int64_t probeSamplesAlong(int64_t pixels, int32_t blockPx);  // along one side: probeSamples is their product
int32_t probeBlockPx(int32_t width, int32_t height);
// Whether the frame runs steady's probe: for its noise samples (Params::steadyNoiseEstimate) or its gain
// (Params::steadyGainCompensation), before steady's temporal passes.
bool probeRuns(const Params& params, const FramePlan& plan);
// The stereo pass of eye e: this eye blended with the other (seed 002 §4.1), into the output.
PassDispatch stereoPass(const PassContext& c, uint32_t e);

// The specialisation constants of a dispatch (constant_id order of common.glsl).
SpecKey passSpecKey(const PassDispatch& d, const Params& params, bool blocked, uint32_t groupX,
                    uint32_t groupY);

}  // namespace steadyxr::core::detail
