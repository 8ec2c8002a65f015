#include "steadyxr/core/params.h"

#include <cmath>
#include <string>

namespace steadyxr::core {
namespace {

struct MethodEntry {
  TemporalMethod method;
  std::string_view name;
};
constexpr MethodEntry kMethods[] = {
    {TemporalMethod::None, "none"},     {TemporalMethod::Fxaa, "fxaa"}, {TemporalMethod::Taa, "taa"},
    {TemporalMethod::Hmtaa, "hmtaa"},   {TemporalMethod::Vtaa, "vtaa"}, {TemporalMethod::Hybrid, "hybrid"},
    {TemporalMethod::Steady, "steady"},
};

bool finite(float v) {
  return std::isfinite(v);
}
bool inUnit(float v) {
  return finite(v) && v >= 0.0f && v <= 1.0f;
}
bool positive(float v) {
  return finite(v) && v > 0.0f;
}

}  // namespace

std::string_view toString(TemporalMethod m) {
  for (const auto& e : kMethods) {
    if (e.method == m) return e.name;
  }
  return "unknown";
}

std::optional<TemporalMethod> parseTemporalMethod(std::string_view name) {
  for (const auto& e : kMethods) {
    if (e.name == name) return e.method;
  }
  return std::nullopt;
}

std::optional<Params> applyMethodName(std::string_view name, Params base) {
  if (name == "default") {
    base.temporal = kDefaultTemporalMethod;
    base.stereo = kDefaultStereo;
    return base;
  }
  if (name == "stereo") {
    base.temporal = TemporalMethod::None;
    base.stereo = true;
    return base;
  }
  constexpr std::string_view kSuffix = "+stereo";
  bool stereo = false;
  if (name.size() > kSuffix.size() && name.substr(name.size() - kSuffix.size()) == kSuffix) {
    stereo = true;
    name.remove_suffix(kSuffix.size());
  }
  const auto m = parseTemporalMethod(name);
  if (!m) return std::nullopt;
  base.temporal = *m;
  base.stereo = stereo;
  return base;
}

std::string methodName(const Params& p) {
  if (p.temporal == TemporalMethod::None && p.stereo) return "stereo";
  std::string s(toString(p.temporal));
  if (p.stereo) s += "+stereo";
  return s;
}

std::string validate(const Params& p, Params* sanitized) {
  const Params def;
  Params out = p;
  std::string first;
  auto check = [&](bool ok, const char* name, auto Params::*field) {
    if (ok) return;
    if (first.empty()) first = std::string("invalid value for ") + name;
    out.*field = def.*field;
  };
  check(parseTemporalMethod(toString(p.temporal)).has_value(), "temporal", &Params::temporal);
  check(inUnit(p.taaAlpha) && p.taaAlpha > 0.0f, "taaAlpha", &Params::taaAlpha);
  check(positive(p.taaClipGamma), "taaClipGamma", &Params::taaClipGamma);
  check(positive(p.hMaxDegPerSec), "hMaxDegPerSec", &Params::hMaxDegPerSec);
  check(inUnit(p.wMin), "wMin", &Params::wMin);
  check(inUnit(p.wLowerBound) && p.wLowerBound <= out.wMin, "wLowerBound", &Params::wLowerBound);
  check(p.sampleCount >= 1 && p.sampleCount <= Params::kMaxSamples, "sampleCount", &Params::sampleCount);
  bool dOk = true;
  for (uint32_t i = 0; i < Params::kMaxSamples; ++i) dOk = dOk && inUnit(p.sampleD[i]);
  check(dOk, "sampleD", &Params::sampleD);
  check(inUnit(p.vtaaAlphaMin), "vtaaAlphaMin", &Params::vtaaAlphaMin);
  check(positive(p.stereoFarDistanceM) || p.stereoFarDistanceM == INFINITY, "stereoFarDistanceM",
        &Params::stereoFarDistanceM);
  check(inUnit(p.steadyAlphaFloor) && p.steadyAlphaFloor > 0.0f, "steadyAlphaFloor",
        &Params::steadyAlphaFloor);
  check(positive(p.steadyClipGamma), "steadyClipGamma", &Params::steadyClipGamma);
  check(positive(p.steadyClipCurvatureKappa), "steadyClipCurvatureKappa", &Params::steadyClipCurvatureKappa);
  check(positive(p.steadyClipCurvatureInner) && p.steadyClipCurvatureInner < out.steadyClipCurvatureKappa,
        "steadyClipCurvatureInner", &Params::steadyClipCurvatureInner);
  check(finite(p.steadyFootprint) && p.steadyFootprint >= 0.0f && p.steadyFootprint <= 0.25f,
        "steadyFootprint", &Params::steadyFootprint);
  check(positive(p.steadyNearestDepthM) || p.steadyNearestDepthM == INFINITY, "steadyNearestDepthM",
        &Params::steadyNearestDepthM);
  check(finite(p.steadyNoiseVariance) && p.steadyNoiseVariance >= 0.0f && p.steadyNoiseVariance <= 1.0f,
        "steadyNoiseVariance", &Params::steadyNoiseVariance);
  check(finite(p.steadyBlurBudgetPx2) && p.steadyBlurBudgetPx2 >= 0.0f, "steadyBlurBudgetPx2",
        &Params::steadyBlurBudgetPx2);
  // Up to 1/2: the code shown is then always one of the two that bracket the estimate.
  check(finite(p.steadyOutputHold) && p.steadyOutputHold >= 0.0f && p.steadyOutputHold <= 0.5f,
        "steadyOutputHold", &Params::steadyOutputHold);
  check(finite(p.stereoDepthTolerance) && p.stereoDepthTolerance >= 0.0f, "stereoDepthTolerance",
        &Params::stereoDepthTolerance);
  check(inUnit(p.stereoBetaMin), "stereoBetaMin", &Params::stereoBetaMin);
  check(positive(p.stereoClipGammaAfterSteady), "stereoClipGammaAfterSteady",
        &Params::stereoClipGammaAfterSteady);
  check(positive(p.resetAngleDeg), "resetAngleDeg", &Params::resetAngleDeg);
  check(positive(p.resetTranslationM), "resetTranslationM", &Params::resetTranslationM);
  if (sanitized) *sanitized = out;
  return first;
}

Params withHudProfile(Params p) {
  p.steadyBlurBudgetPx2 = kHudBlurBudgetPx2;
  p.steadyClipHoldsCurrent = true;
  return p;
}

}  // namespace steadyxr::core
