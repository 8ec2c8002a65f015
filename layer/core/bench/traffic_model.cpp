#include "traffic_model.h"

#include <algorithm>

#include "steadyxr/core/filter.h"

namespace steadyxr::bench {
namespace {

using core::TemporalMethod;

double texelBytes(VkFormat f) {
  return f == VK_FORMAT_R16G16B16A16_SFLOAT ? 8.0 : 4.0;
}

}  // namespace

Traffic modelTraffic(const core::Params& params, VkFormat inputFormat, bool blocked) {
  const double in = texelBytes(inputFormat);
  const double out = in;  // the bench's output has the input's format
  const double hist = texelBytes(core::historyFormat(params, inputFormat));
  const double window = blocked ? 36.0 / 16.0 : 9.0;  // fetches of a 3x3 (6x6 per 4x4 block)
  const TemporalMethod m = params.temporal;
  const bool temporal = m != TemporalMethod::None && m != TemporalMethod::Fxaa;
  const bool stereo = params.stereo;
  Traffic t;
  if (m == TemporalMethod::None && !stereo) {  // the copy
    t.readBytes = in;
    t.writeBytes = out;
    t.fetches = 1;
    t.stores = 1;
    return t;
  }
  if (m == TemporalMethod::Fxaa) {
    // 3x3 luma plus the two edge-end taps (the data-dependent edge search adds up to 12 more).
    t.readBytes += in;
    t.samples += 11;
  } else if (temporal) {
    // src0's 3x3 (hmtaa: its centre), the history's taps, the app's alpha (src0 again: cached;
    // the 3x3 passes take it from their block, hmtaa fetches it).
    const bool interpolated = m == TemporalMethod::Hmtaa || m == TemporalMethod::Hybrid;
    const double taps = (interpolated ? std::max<uint32_t>(params.sampleCount, 1) : 1.0) *
                        (params.historyFilter == core::HistoryFilter::CatmullRom ? 5.0 : 1.0);
    t.readBytes += in + hist;
    t.fetches += m == TemporalMethod::Hmtaa ? 1.0 : window;
    if (hist == 4.0)
      t.fetches += 4.0 * taps;  // the 8-bit history: decoded before filtering (common.glsl tapSrc1)
    else
      t.samples += taps;
    if (!stereo && m == TemporalMethod::Hmtaa) t.fetches += 1;  // alphaOf
    // Round 20: steady's held 8-bit output reads last frame's shown codes and writes this frame's.
    if (m == TemporalMethod::Steady && params.steadyOutputHold > 0.0f && !stereo && out == 4.0) {
      t.readBytes += 4.0;
      t.writeBytes += 4.0;
      t.fetches += 1;
      t.stores += 1;
    }
  }
  if (m != TemporalMethod::None) {  // the stage-1 pass writes the history (fxaa: when stereo reads it)
    const bool writesHistory = temporal || stereo;
    t.writeBytes += (writesHistory ? hist : 0.0) + (stereo ? 0.0 : out);
    t.stores += (writesHistory ? 1.0 : 0.0) + (stereo ? 0.0 : 1.0);
  }
  if (stereo) {
    // This eye's 3x3 and the other eye's bilinear tap, both from stage 1's history (or the inputs
    // for `stereo` alone, where the app's alpha is src0 again); the app's alpha otherwise is a
    // third image.
    const bool fromHistory = m != TemporalMethod::None;
    const double src = fromHistory ? hist : in;
    t.readBytes += 2.0 * src + (fromHistory ? in : 0.0);
    t.writeBytes += out;
    t.fetches += window + 1;
    t.samples += 1;
    t.stores += 1;
  }
  return t;
}

}  // namespace steadyxr::bench
