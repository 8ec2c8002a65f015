// Method selection and tunable parameters of the filter core. Value type; parse/format
// helpers report bad input as an error string instead of throwing.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace steadyxr::core {

enum class TemporalMethod : uint8_t {
  None,    // pass-through
  Fxaa,    // FXAA 3.11-style single-frame edge filter (seed 001 §4.3)
  Taa,     // pose reprojection + YCoCg 3x3 variance clipping + constant alpha (seed 001, 002 §4.2)
  Hmtaa,   // head-movement TAA, seed 003 Eq. 1-5
  Vtaa,    // variance-optimal blending, seed 002 Eq. 4, 10, 11
  Hybrid,  // hmtaa reprojection + A(h), with vtaa's per-pixel weight in place of the clip
};

// The shipped default temporal method: decided by the evaluation (eval/), one line to change.
inline constexpr TemporalMethod kDefaultTemporalMethod = TemporalMethod::Hybrid;

// How the temporal passes resample the reprojected history.
enum class HistoryFilter : uint8_t {
  Bilinear,    // one bilinear tap: cheapest, blurs a little on every sub-pixel reprojection
  CatmullRom,  // five bilinear taps (Catmull-Rom without its corner taps): stays sharp
};

enum class InvocationBlock : uint8_t { Auto, OnePixel, FourByFour };

struct Params {
  TemporalMethod temporal = kDefaultTemporalMethod;
  bool stereo = true;  // stereo blending after the temporal pass (display only)

  // taa
  float taaAlpha = 0.1f;      // weight of the current frame
  float taaClipGamma = 1.0f;  // clip box = mean +- gamma * sigma (YCoCg); also hybrid's history
                              // clip and stereo's clip of the other eye (RGB box)

  // hmtaa (seed 003 §5.2.2 defaults)
  float hMaxDegPerSec = 25.0f;
  float wMin = 0.3f;
  float wLowerBound = 0.1f;  // w_lb of Eq. 5
  static constexpr uint32_t kMaxSamples = 4;
  uint32_t sampleCount = 1;                                                      // n past samples
  std::array<float, kMaxSamples> sampleD{2.0f / 3.0f, 1.0f / 3.0f, 0.0f, 0.0f};  // d_i in [0,1]

  // vtaa / hybrid
  float vtaaAlphaMin = 0.05f;  // lower clamp of alpha' (the weight of the current frame)

  // stereo (seed 002 §4.1, §5.2)
  float stereoFarDistanceM = 10.0f;    // assumed scene distance when no depth is given
  float stereoDepthTolerance = 0.05f;  // relative depth difference that rejects the other eye
  // Lower clamp of beta (the weight of this eye). The other eye is a sample as noisy as this
  // one, so it should never outweigh it (beta >= 0.5). 0.9 measured (eval, 256x256): 0.7 pulls
  // the eyes of the thin-geometry scene closer together than ground truth's are (stereo gap
  // +177 %, RMSE +0.6 %); 0.9 brings every scenario's stereo difference closer to ground truth's.
  float stereoBetaMin = 0.9f;

  HistoryFilter historyFilter = HistoryFilter::Bilinear;

  // The caller jitters the render (ViewFrame::jitterPx): every frame, also one with a jitter of 0,
  // goes through the un-jittering fetch (bilinear at c - jitter; at 0 it reads the texel exactly),
  // so the pipeline does not change, and recompile, when the jitter starts.
  bool jitteredInput = false;

  // Pixels per shader invocation in every pass but fxaa: Auto picks 4x4 on a CPU device
  // (lavapipe; shared 3x3 neighbourhood fetches, and faster even where none are shared) and 1x1
  // on a GPU (coalesced accesses).
  InvocationBlock invocationBlock = InvocationBlock::Auto;

  // history reset
  float resetAngleDeg = 30.0f;  // a pose jump larger than this between frames resets history
  float resetTranslationM = 0.5f;
};

std::string_view toString(TemporalMethod m);
std::optional<TemporalMethod> parseTemporalMethod(std::string_view name);

// Full method names as users type them: "none", "fxaa", "taa", "hmtaa", "vtaa", "hybrid",
// "stereo" (stereo only), "<temporal>+stereo", and "default". Returns nullopt for unknown names.
// Only the method fields of `base` are changed.
std::optional<Params> applyMethodName(std::string_view name, Params base = {});
std::string methodName(const Params& p);  // inverse of applyMethodName

// Checks ranges (NaN, negative, out of [0,1], ...). Returns an empty string when valid, else a
// human-readable message naming the first bad field; `sanitized` gets safe defaults for bad fields.
std::string validate(const Params& p, Params* sanitized = nullptr);

}  // namespace steadyxr::core
