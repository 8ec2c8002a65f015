#include "head_locked_detector.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include <glm/geometric.hpp>

namespace steadyxr::eval {
namespace {

// The luma's 4x4 block means on the texel corners (0..w, 0..h): corner (x, y) holds the mean of the
// texels x-2..x+1, y-2..y+1 (clamped into the image). Stored in an Image of (w+1) x (h+1), channel 0.
Image blockMeans(const Image& image) {
  const int w = image.width, h = image.height;
  std::vector<float> luma(size_t(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float* c = image.at(x, y);
      luma[size_t(y) * w + x] = 0.25f * c[0] + 0.5f * c[1] + 0.25f * c[2];
    }
  Image means(w + 1, h + 1);
  for (int y = 0; y <= h; ++y)
    for (int x = 0; x <= w; ++x) {
      float sum = 0.0f;
      for (int j = -2; j < 2; ++j)
        for (int i = -2; i < 2; ++i)
          sum += luma[size_t(std::clamp(y + j, 0, h - 1)) * w + size_t(std::clamp(x + i, 0, w - 1))];
      means.at(x, y)[0] = sum / 16.0f;
    }
  return means;
}

// The block mean at a continuous point (bilinear between corners); false outside the image.
bool blockMeanAt(const Image& means, glm::vec2 point, float* out) {
  const int w = means.width - 1, h = means.height - 1;
  if (!(point.x >= 2.0f && point.y >= 2.0f && point.x <= float(w - 2) && point.y <= float(h - 2)))
    return false;
  const int x0 = std::min(int(point.x), w - 1), y0 = std::min(int(point.y), h - 1);
  const float fx = point.x - float(x0), fy = point.y - float(y0);
  const float top = means.at(x0, y0)[0] * (1 - fx) + means.at(x0 + 1, y0)[0] * fx;
  const float bottom = means.at(x0, y0 + 1)[0] * (1 - fx) + means.at(x0 + 1, y0 + 1)[0] * fx;
  *out = top * (1 - fy) + bottom * fy;
  return true;
}

// The render's noise in one pixel's luma: Donoho and Johnstone's median |d| / 0.6745 over the finest
// diagonal detail at the samples (what the layer's probe takes, noise_estimate.h), d normed to the noise.
float pixelNoise(const Image& image, int blockPx) {
  std::vector<float> details;
  auto luma = [&](int x, int y) {
    const float* c = image.at(x, y);
    return 0.25f * c[0] + 0.5f * c[1] + 0.25f * c[2];
  };
  for (int y = blockPx / 2; y + 1 < image.height; y += blockPx)
    for (int x = blockPx / 2; x + 1 < image.width; x += blockPx) {
      const float corners = luma(x - 1, y - 1) + luma(x + 1, y - 1) + luma(x - 1, y + 1) + luma(x + 1, y + 1);
      const float edges = luma(x, y - 1) + luma(x - 1, y) + luma(x + 1, y) + luma(x, y + 1);
      const float d = std::abs(corners - 2.0f * edges + 4.0f * luma(x, y)) / 6.0f;
      if (d > 0.0f) details.push_back(d);  // a flat 3x3 says nothing about noise
    }
  if (details.empty()) return 0.0f;
  std::nth_element(details.begin(), details.begin() + details.size() / 2, details.end());
  return details[details.size() / 2] / 0.6745f;
}

}  // namespace

bool HeadLockedDetector::observe(int frame, const std::array<const Image*, 2>& images,
                                 const std::array<EyeCamera, 2>& cams) {
  std::array<Image, 2> means;
  for (int eye = 0; eye < 2; ++eye) means[eye] = blockMeans(*images[eye]);
  const bool sameSize = haveReference_ && means[0].width == reference_[0].blocks.width &&
                        means[0].height == reference_[0].blocks.height &&
                        means[1].width == reference_[1].blocks.width &&
                        means[1].height == reference_[1].blocks.height;
  if (!sameSize) {  // the first frame, or the app changed its render size: start an epoch
    for (int eye = 0; eye < 2; ++eye) {
      reference_[eye] = {std::move(means[eye]), cams[eye]};
      testimony_[eye].clear();  // the samples lie elsewhere now
    }
    haveReference_ = true;
    return decided();
  }
  HeadLockedEpoch epoch;
  epoch.frame = frame;
  bool epochEnds = false;
  // This frame's testimonies; they count only if the frame ends the epoch (one testimony a sample an epoch).
  std::vector<Testimony*> saidHeadLocked, saidWorld;
  for (int eye = 0; eye < 2; ++eye) {
    const Reference& ref = reference_[eye];
    // Two block means differ by their noise times sqrt(2) / 4 (16 texels each); 3 of those, and never
    // less than a code, is a match; a mismatch is 4 times that (the gap between is no evidence).
    const float noise = pixelNoise(*images[eye], kBlockPx) * std::sqrt(2.0f) / 4.0f;
    const float match = std::max(1.0f / 255.0f, 3.0f * noise), mismatch = 4.0f * match;
    int samples = 0, moved = 0;
    const int columns = (images[eye]->width + kBlockPx / 2) / kBlockPx;
    const int rows = (images[eye]->height + kBlockPx / 2) / kBlockPx;
    std::vector<Testimony>& record = testimony_[eye];
    record.resize(size_t(columns) * rows);
    for (int y = kBlockPx / 2; y < images[eye]->height; y += kBlockPx)
      for (int x = kBlockPx / 2; x < images[eye]->width; x += kBlockPx) {
        Testimony& said = record[size_t(y / kBlockPx) * columns + x / kBlockPx];
        const glm::vec2 here{float(x), float(y)};
        float before = 0.0f, same = 0.0f, carried = 0.0f;
        if (!blockMeanAt(ref.blocks, here, &before)) continue;
        ++samples;
        glm::vec2 there;
        if (!projectDirection(cams[eye], pixelDirection(ref.cam, here.x, here.y), &there)) continue;
        if (glm::length(there - here) < kShiftPx) continue;
        ++moved;
        if (!blockMeanAt(means[eye], here, &same) || !blockMeanAt(means[eye], there, &carried)) continue;
        // The two hypotheses must predict different values here: this frame's block at `here` is the
        // reference's at `here` if head-locked and the reference's at `back` if world. A near-flat picture
        // (or aliasing's slow moire) predicts the same either way and says nothing.
        glm::vec2 back;
        float worldBefore = 0.0f;
        if (!projectDirection(ref.cam, pixelDirection(cams[eye], here.x, here.y), &back) ||
            !blockMeanAt(ref.blocks, back, &worldBefore) || std::abs(worldBefore - before) <= mismatch)
          continue;
        const float headLockedResidual = std::abs(same - before), worldResidual = std::abs(carried - before);
        if (headLockedResidual <= match && worldResidual > mismatch) saidHeadLocked.push_back(&said);
        if (worldResidual <= match && headLockedResidual > mismatch) saidWorld.push_back(&said);
      }
    if (samples > 0 && 2 * moved >= samples) epochEnds = true;
  }
  if (!epochEnds) return decided();
  for (Testimony* said : saidHeadLocked) ++said->headLocked;
  for (Testimony* said : saidWorld) ++said->world;
  epoch.headLocked = int(saidHeadLocked.size());
  epoch.world = int(saidWorld.size());
  // Head-locked content stays where it is on the screen: a sample counts once it has testified so in
  // kEpochsToDecide epochs and never for the world (aliasing's moire, which does not move with the world
  // either, testifies at places that change from epoch to epoch).
  int steady = 0;
  for (const auto& record : testimony_)
    for (const Testimony& said : record)
      steady += said.headLocked >= kEpochsToDecide && said.world == 0 ? 1 : 0;
  epoch.evidence = steady >= kEvidenceSamples;
  epoch.steadySamples = steady;
  epochs_.push_back(epoch);
  if (epoch.evidence && decidedFrame_ < 0) decidedFrame_ = frame;
  for (int eye = 0; eye < 2; ++eye) reference_[eye] = {std::move(means[eye]), cams[eye]};
  return decided();
}

std::string headLockedCsvRow(const HeadLockedDetector& detector) {
  int evidence = 0;
  std::ostringstream list;  // frame:head-locked/world, * where the epoch counts
  for (const HeadLockedEpoch& e : detector.epochs()) {
    evidence += e.evidence ? 1 : 0;
    list << (list.tellp() > 0 ? " " : "") << e.frame << ':' << e.headLocked << '/' << e.world << '/'
         << e.steadySamples << (e.evidence ? "*" : "");
  }
  std::ostringstream row;
  row << detector.decidedFrame() << ',' << detector.epochs().size() << ',' << evidence << ',' << list.str();
  return row.str();
}

}  // namespace steadyxr::eval
