// Round 41's study: can a layer tell, from its input frames and the poses it is told, that the app draws
// head-locked content (a HUD, a reticle, subtitles) into its eye images, so that it can switch itself to
// the profile `hud` for the session? Rounds 18, 23 and 24 looked for head-locked pixels, to treat them
// alone, and found no rule that is both quick and free for the world; a switch of the whole frame needs
// only to know that the app draws such content at all, and may take many frames to learn it.
//
// The detector sees what the layer's probe could: the luma of the app's frame, as 4x4-pixel block means
// (round 31's blocks: a wire's coverage kept, the rounding averaged) at one sample per 4 px block, and the
// submitted (tracked) poses, no depth, no app motion vectors. Epochs: a reference frame's block means are
// kept; once the head's rotation since the reference moves the world by at least kShiftPx at a sample,
// that sample gives its evidence in this frame:
// - head-locked: this frame at the same pixel matches the reference, and at the place where the world
//   has carried the reference's point it does not;
// - world: the reverse;
// and only where the two hypotheses predict different values for the sample. An epoch ends when half of an
// eye's samples have moved that far; only that frame's evidence counts (once a sample an epoch), and the
// frame becomes the new reference. Measured, not built in the layer: docs/method-history.md, round 41.
#pragma once

#include "camera.h"
#include "image.h"

#include "steadyxr/core/params.h"

#include <array>
#include <string>
#include <vector>

namespace steadyxr::eval {

struct HeadLockedEpoch {
  int frame = 0;          // the frame that ended it
  int headLocked = 0;     // samples (both eyes) with head-locked evidence
  int world = 0;          // samples with world evidence
  int steadySamples = 0;  // samples that have testified head-locked in kEpochsToDecide epochs, never world
  bool evidence = false;  // kEvidenceSamples of them: the decision
};

class HeadLockedDetector {
 public:
  // A sample moves at least this far before it testifies: a 4x4 block mean moved by half its side has
  // kept less than half of its texels, so the two hypotheses predict clearly different means.
  static constexpr float kShiftPx = 2.0f;
  static constexpr int kBlockPx = 4;
  // The decision: this many samples (both eyes) that testified head-locked in this many epochs, never world.
  static constexpr int kEvidenceSamples = 8;
  static constexpr int kEpochsToDecide = 2;

  // One frame of both eyes (display-encoded images as the app drew them, the cameras the layer is told).
  // Returns true once the app has been found to draw head-locked content (and from then on).
  bool observe(int frame, const std::array<const Image*, 2>& images, const std::array<EyeCamera, 2>& cams);
  bool decided() const { return decidedFrame_ >= 0; }
  int decidedFrame() const { return decidedFrame_; }
  const std::vector<HeadLockedEpoch>& epochs() const { return epochs_; }

 private:
  struct Reference {
    Image blocks;  // the 4x4 block means of the luma, one channel in rgb[0] of each pixel (see .cpp)
    EyeCamera cam;
  };
  struct Testimony {
    int headLocked = 0;
    int world = 0;
  };
  std::array<Reference, 2> reference_;
  std::array<std::vector<Testimony>, 2> testimony_;  // per eye, per sample, over the session
  bool haveReference_ = false;
  int decidedFrame_ = -1;
  std::vector<HeadLockedEpoch> epochs_;
};

// autohud.csv: per case, the frame the detector decided in (-1: never) and its epochs.
inline constexpr const char* kHeadLockedCsvHeader = "case,decided_frame,epochs,evidence_epochs,epoch_list";
std::string headLockedCsvRow(const HeadLockedDetector& detector);  // without the case's label

}  // namespace steadyxr::eval
