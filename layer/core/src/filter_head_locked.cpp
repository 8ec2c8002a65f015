#include "filter_head_locked.h"

#include <glm/geometric.hpp>

#include "filter_formats.h"
#include "filter_geometry.h"
#include "filter_passes.h"

namespace steadyxr::core::detail {

namespace {

// Whether the rotation since the reference has carried at least half of the eye's samples (those whose block
// lies inside the eye) kHeadLockedShiftPx or more.
bool carriedHalfTheSamples(const glm::mat4& referenceToNow, VkExtent2D size, int32_t blockPx) {
  const float width = static_cast<float>(size.width), height = static_cast<float>(size.height);
  int64_t samples = 0, moved = 0;
  for (int64_t y = blockPx / 2; y < int64_t(size.height); y += blockPx)
    for (int64_t x = blockPx / 2; x < int64_t(size.width); x += blockPx) {
      const glm::vec2 here{float(x), float(y)};
      if (here.x < 2.0f || here.y < 2.0f || here.x > width - 2.0f || here.y > height - 2.0f) continue;
      ++samples;
      const glm::vec4 h = referenceToNow * glm::vec4(here, 1.0f, 0.0f);
      if (!(h.z > 1e-12f)) continue;  // behind the view now
      moved += glm::length(glm::vec2(h) / h.z - here) >= kHeadLockedShiftPx ? 1 : 0;
    }
  return samples > 0 && 2 * moved >= samples;
}

}  // namespace

VkExtent2D headLockedRecordExtent(VkExtent2D eyeSize, int32_t blockPx) {
  return {static_cast<uint32_t>(probeSamplesAlong(eyeSize.width, blockPx)),
          static_cast<uint32_t>(probeSamplesAlong(eyeSize.height, blockPx))};
}

std::array<HeadLockedEyeStep, 2> HeadLockedSwitch::plan(const StereoFrame& frame,
                                                        const std::array<bool, 2>& poseOk,
                                                        const std::array<int32_t, 2>& probeBlockPx,
                                                        bool jittered) {
  std::array<HeadLockedEyeStep, 2> steps{};
  const uint32_t n = frame.viewCount;
  for (uint32_t e = 0; e < n; ++e)
    if (!poseOk[e]) return steps;
  if (jittered) return steps;
  auto takeFrame = [&] {
    for (uint32_t e = 0; e < n; ++e) {
      const ViewFrame& v = frame.views[e];
      reference_[e] = Reference{v.pose, v.fov, v.color.rect.extent, probeBlockPx[e]};
    }
  };
  bool newStart = false;
  for (uint32_t e = 0; e < n; ++e)
    newStart = newStart || !reference_[e] ||
               !sameExtent(reference_[e]->size, frame.views[e].color.rect.extent) ||
               reference_[e]->blockPx != probeBlockPx[e];
  if (newStart) {  // the first frame, or the samples lie elsewhere now: their testimonies start again
    for (uint32_t e = 0; e < n; ++e) steps[e].step = HeadLockedStep::TakeReference;
    takeFrame();
    return steps;
  }
  bool epochEnds = false;
  for (uint32_t e = 0; e < n; ++e) {
    const Reference& ref = *reference_[e];
    const ViewFrame& v = frame.views[e];
    steps[e].referenceToNow = reprojection(ref.pose, ref.fov, ref.size, v.pose, v.fov, v.color.rect.extent);
    epochEnds = epochEnds || carriedHalfTheSamples(steps[e].referenceToNow, ref.size, ref.blockPx);
  }
  if (!epochEnds) return {};
  for (uint32_t e = 0; e < n; ++e) steps[e].step = HeadLockedStep::Testify;
  takeFrame();
  return steps;
}

void HeadLockedSwitch::noteSteadySamples(uint32_t samples, uint64_t frameIndex) {
  HeadLockedEvidence& e = evidence_ ? *evidence_ : evidence_.emplace();
  ++e.epochs;
  if (e.epochs == 1 || frameIndex > e.frame) {  // slots are read in any order: keep the newest
    e.frame = frameIndex;
    e.steadySamples = samples;
  }
  if (samples >= kHeadLockedEvidenceSamples && (!e.decidedFrame || frameIndex < *e.decidedFrame))
    e.decidedFrame = frameIndex;
}

}  // namespace steadyxr::core::detail
