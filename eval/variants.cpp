#include "variants.h"

#include "steadyxr/core/jitter.h"

#include <sstream>
#include <string_view>

namespace steadyxr::eval {

std::vector<std::string> defaultMethods(bool sweeps) {
  std::vector<std::string> m;
  for (const char* base : {"none", "fxaa", "msaa2", "msaa4", "taa", "hmtaa", "vtaa", "hybrid", "steady"}) {
    m.push_back(base);
    m.push_back(std::string(base) + "+stereo");
  }
  m.push_back("default");
  // Jittered variants of the temporal methods: seed 001's TAA is jittered, as every real TAA.
  for (const char* base : {"taa", "hmtaa", "vtaa", "hybrid", "steady", "default"})
    m.push_back(std::string(base) + "+jitter");
  m.push_back("oracle");
  m.push_back("oracle+jitter");
  if (sweeps) {
    for (const char* s :
         {"hmtaa@hmax=10", "hmtaa@hmax=50", "hmtaa@wmin=0.15", "hmtaa@wmin=0.5", "taa@alpha=0.05",
          "taa@alpha=0.2", "default@floor=0.125", "default@floor=0.03125", "default@blur=0.5",
          "default@footprint=0.0625", "default@clip=1", "default@catmull=1"}) {
      m.push_back(s);
    }
  }
  return m;
}

// "<method>[@key=value]...": a method name applyMethodName understands (or msaa2/msaa4[+stereo])
// with parameter overrides for sweeps.
bool parseVariant(const std::string& spec, Variant* v, std::string* error) {
  std::vector<std::string> parts;
  std::stringstream ss(spec);
  for (std::string p; std::getline(ss, p, '@');) parts.push_back(p);
  if (parts.empty()) {
    *error = "empty method";
    return false;
  }
  std::string base = parts[0];
  v->source = 1;
  if (base == "oracle" || base == "oracle+jitter") {
    v->oracle = true;
    v->jitter = base == "oracle+jitter";  // the layer's jittered frames, else the unjittered ones
    v->name = spec;
    v->params = *core::applyMethodName("none");
    if (parts.size() > 1) {
      *error = "the oracle takes no parameters";
      return false;
    }
    return true;
  }
  constexpr std::string_view kJitter = "+jitter";
  if (base.ends_with(kJitter)) {
    v->jitter = true;
    base.resize(base.size() - kJitter.size());
  }
  for (int s : {2, 4}) {
    const std::string msaa = "msaa" + std::to_string(s);
    if (base == msaa || base == msaa + "+stereo") {
      // MSAA images go through the core as pass-through, or stereo blending only.
      v->source = s;
      base = base == msaa ? "none" : "stereo";
    }
  }
  auto params = core::applyMethodName(base);
  if (!params) {
    *error = "unknown method '" + parts[0] + "'";
    return false;
  }
  if (v->jitter) {
    // As the layer: jitter only where the core un-jitters it (else it would only shake the image).
    if (v->source != 1 || !core::undoesJitter(params->temporal)) {
      *error = "'" + parts[0] + "': only the history-blending temporal methods can be jittered";
      return false;
    }
    params->jitteredInput = true;
  }
  for (size_t i = 1; i < parts.size(); ++i) {
    const auto eq = parts[i].find('=');
    if (eq == std::string::npos) {
      *error = "bad parameter '" + parts[i] + "' in '" + spec + "'";
      return false;
    }
    const std::string key = parts[i].substr(0, eq);
    float value = 0.0f;
    try {
      value = std::stof(parts[i].substr(eq + 1));
    } catch (...) {
      *error = "bad value in '" + parts[i] + "'";
      return false;
    }
    if (key == "hmax")
      params->hMaxDegPerSec = value;
    else if (key == "wmin")
      params->wMin = value;
    else if (key == "wlb")
      params->wLowerBound = value;
    else if (key == "amin")
      params->vtaaAlphaMin = value;
    else if (key == "alpha")
      params->taaAlpha = value;
    else if (key == "gamma")
      params->taaClipGamma = value;
    else if (key == "beta")
      params->stereoBetaMin = value;
    else if (key == "ivbeta")  // after steady: stereo beta from inverse error variances, 0 = Eq. 4
      params->stereoInverseVariance = value != 0.0f;
    else if (key == "tapcurv")  // after steady: the other eye's tap corrected by this eye's curvature
      params->stereoTapCurvature = value != 0.0f;
    else if (key == "sclip")  // after steady: the stereo pass's clip box gamma
      params->stereoClipGammaAfterSteady = value;
    else if (key == "d")
      params->sampleD[0] = value;
    else if (key == "catmull")
      params->historyFilter = value != 0.0f ? core::HistoryFilter::CatmullRom : core::HistoryFilter::Bilinear;
    else if (key == "fpenc")
      params->steadyFootprintEncoded = value != 0.0f;
    else if (key == "blurnoise")  // round 26: the blur guard traded against the render's noise
      params->steadyBlurNoiseTrade = value != 0.0f;
    else if (key == "bluraxis")
      params->steadyHistoryBlurPerAxis = value != 0.0f;
    else if (key == "floor")  // steady's ablation switches and constants (core::Params)
      params->steadyAlphaFloor = value;
    else if (key == "conf")
      params->steadyConfidence = value != 0.0f;
    else if (key == "reject")
      params->steadyClipRejects = value != 0.0f;
    else if (key == "noiseest")  // rounds 13-15 (the default since 15): steady estimates the render's noise
      params->steadyNoiseEstimate = value != 0.0f;
    else if (key == "noisechange")  // round 15: 0 = round 14's estimate, no test for a change as a whole
      params->steadyNoiseChangeTest = value != 0.0f;
    else if (key == "gain")  // round 16 (the default): 0 = no gain compensation (round 15's default)
      params->steadyGainCompensation = value != 0.0f;
    else if (key == "gainall")  // round 17 (the default): 0 = round 16's rule, the box-rejected history alone
      params->steadyGainRelightsAdmitted = value != 0.0f;
    else if (key == "cut")  // round 31 (the default): a frame the pose does not explain starts afresh
      params->steadyUnexplainedFrameResets = value != 0.0f;
    else if (key == "noisetime")  // round 14: 0 = round 13's estimate, the frame's own detail alone
      params->steadyNoiseResidualOverTime = value != 0.0f;
    else if (key == "noisevar") {  // told instead: a variance per linear RGB channel, < 0: the scene's own
      params->steadyNoiseEstimate = false;
      if (value < 0.0f)
        v->noiseOracle = -value;
      else
        params->steadyNoiseVariance = value;
    } else if (key == "autohud")  // round 41's study (head_locked_detector.h): switches to the profile hud
      v->autoHud = value != 0.0f;
    else if (key == "resolved")  // round 48 (the default): 0 = no item 15 (round 47's default)
      params->steadyResolvedEdges = value != 0.0f;
    else if (key == "hudswitch")  // round 42 (the default): 0 = no head-locked switch (round 41's default)
      params->steadyHeadLockedSwitch = value != 0.0f;
    else if (key == "hold")  // round 20: the 8-bit output's hysteresis in codes beyond 1/2 (0 = rounding)
      params->steadyOutputHold = value;
    else if (key == "boxcur")
      params->steadyClipHoldsCurrent = value != 0.0f;
    else if (key == "curvbox")
      params->steadyClipCurvature = value != 0.0f;
    else if (key == "curvcentre")  // round 7, with curvbox=1: the curvature box one-sided
      params->steadyClipCurvatureCentred = value != 0.0f;
    else if (key == "curvgate")  // round 10 (an option): one-sided only where the history lags one side
      params->steadyClipCurvatureCentredGated = value != 0.0f;
    else if (key == "curvinner")  // with curvcentre=1: the interval's inner bound (0 < inner < kappa)
      params->steadyClipCurvatureInner = value;
    else if (key == "quantsrgb")  // the clip's floor half an sRGB step at the level (the default; =0: linear)
      params->steadyClipQuantSrgb = value != 0.0f;
    else if (key == "curvkappa")  // with curvbox=1
      params->steadyClipCurvatureKappa = value;
    else if (key == "blur")
      params->steadyBlurBudgetPx2 = value;
    else if (key == "clip")
      params->steadyClipGamma = value;
    else if (key == "footprint")
      params->steadyFootprint = value;
    else if (key == "jrecentre")
      params->steadyJitterRecentred = value != 0.0f;
    else if (key == "near")  // the stereo pass's nearest content without depth (round 8: steady no longer)
      params->steadyNearestDepthM = value;
    else if (key == "interp")
      params->steadyInterpolated = value != 0.0f;
    else if (key == "history" && (value == 16.0f || value == 8.0f))  // bits per channel
      params->historyFormat =
          value == 16.0f ? core::HistoryFormat::Rgba16f : core::HistoryFormat::Rgba8Dithered;
    else if (key == "dither" && params->historyFormat != core::HistoryFormat::Rgba16f)  // after history=8
      params->historyFormat =
          value != 0.0f ? core::HistoryFormat::Rgba8Dithered : core::HistoryFormat::Rgba8Nearest;
    else {
      *error =
          "unknown parameter '" + key +
          "' (hmax, wmin, wlb, amin, alpha, gamma, beta, ivbeta, tapcurv, sclip, d, catmull, floor, conf, "
          "reject, boxcur, curvbox, curvkappa, clip, blur, blurnoise, footprint, fpenc, bluraxis, "
          "jrecentre, near, interp, curvcentre, curvgate, curvinner, quantsrgb, noiseest, noisetime, "
          "noisechange, gain, gainall, cut, hudswitch, autohud, hold, resolved, noisevar, history=16|8, "
          "dither after history=8)";
      return false;
    }
    v->sweep = true;
  }
  const std::string problem = core::validate(*params);
  if (!problem.empty()) {
    *error = "method '" + spec + "': " + problem;
    return false;
  }
  v->params = *params;
  v->name = spec;
  return true;
}

}  // namespace steadyxr::eval
