// Round 42 (Params::steadyHeadLockedSwitch): does the app draw head-locked content (a HUD, a reticle,
// subtitles) into its eye images? Round 41 measured the question in the harness (eval/head_locked_detector.h,
// docs/method-history.md); this is the filter's own answer, from what its probe sees.
//
// The host keeps the epochs, from the poses alone: a reference frame per eye, and the frame where the head's
// rotation has carried half of an eye's probe samples kHeadLockedShiftPx away from where they were in it
// ends the epoch. In that frame the probe (shaders/probe.glsl, observeHeadLocked) compares each sample's 4x4
// block of displayed luma with the reference's, kept per sample in the eye's record image: matched at the
// same pixel and not where the world carried it, the sample testifies head-locked; the reverse, world. Since
// round 43 the world may also have moved by whole pixels (content drawn without filtering), so where it
// carried a sample is also each of the four roundings of its move. The frame becomes the new reference.
// The probe counts the samples that have testified head-locked in 2 epochs and never for the world; the
// host reads the count back with the frame's records, and kHeadLockedEvidenceSamples of them decide for the
// session.
#pragma once

#include <array>
#include <cstdint>
#include <optional>

#include <vulkan/vulkan.h>
#include <glm/mat4x4.hpp>

#include "steadyxr/core/filter.h"
#include "steadyxr/core/frame.h"

namespace steadyxr::core::detail {

// A sample testifies once the world has moved it this far: a 4x4 block mean moved by half its side has
// kept less than half of its texels, so the two hypotheses predict clearly different means (round 41).
constexpr float kHeadLockedShiftPx = 2.0f;
// The decision: this many samples (both eyes) that testified head-locked in kHeadLockedEpochsToDecide
// epochs and never for the world (round 41, set before any run; shaders/probe.glsl has the same 2).
constexpr uint32_t kHeadLockedEvidenceSamples = 8;
// The record's word in the gain record (noise_estimate.h; the probe adds the count there).
constexpr uint32_t kHeadLockedCountWord = 8;

// What the probe of one eye does for the detector this frame (PassUniforms::headLockedStep).
enum class HeadLockedStep : int32_t {
  None = 0,  // nothing: the record is left as it is
  TakeReference =
      1,        // a new start (the first frame, another size): the record holds this frame, no testimony
  Testify = 2,  // an epoch ends: testify against the record, then it holds this frame
};

struct HeadLockedEyeStep {
  HeadLockedStep step = HeadLockedStep::None;
  // Pixel (x, y, 1, 0) of the reference view -> homogeneous pixel of this frame's view: the head's rotation
  // alone (the world at infinity), as round 41's model.
  glm::mat4 referenceToNow{0.0f};
};

class HeadLockedSwitch {
 public:
  // This frame's steps, the same for every eye (an epoch ends for both), from the views' poses and sizes and
  // the probe's block side per eye. Nothing while a pose is not finite or the input is jittered (the jitter
  // moves the grid under head-locked content too).
  std::array<HeadLockedEyeStep, 2> plan(const StereoFrame& frame, const std::array<bool, 2>& poseOk,
                                        const std::array<int32_t, 2>& probeBlockPx, bool jittered);
  // The next frame takes its reference afresh (its probe did not run: a pipeline still compiling).
  void restartEpochs() { reference_ = {}; }
  // A testifying frame's count of steady samples, read back with its records.
  void noteSteadySamples(uint32_t samples, uint64_t frameIndex);
  bool decided() const { return evidence_ && evidence_->decidedFrame; }
  const std::optional<HeadLockedEvidence>& evidence() const { return evidence_; }

 private:
  struct Reference {
    Pose pose;
    Fov fov;
    VkExtent2D size{};
    int32_t blockPx = 0;
  };
  std::array<std::optional<Reference>, 2> reference_;
  std::optional<HeadLockedEvidence> evidence_;
};

// The record image of an eye: one texel a probe sample (the probe's grid for blocks of `blockPx`).
VkExtent2D headLockedRecordExtent(VkExtent2D eyeSize, int32_t blockPx);

}  // namespace steadyxr::core::detail
