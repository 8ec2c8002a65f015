#include "config.h"

#include <sys/stat.h>
#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace steadyxr::layer {
namespace {

std::string trim(std::string_view s) {
  size_t b = 0;
  size_t e = s.size();
  while (b < e && std::isspace(static_cast<unsigned char>(s[b]))) ++b;
  while (e > b && std::isspace(static_cast<unsigned char>(s[e - 1]))) --e;
  return std::string(s.substr(b, e - b));
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

std::optional<bool> parseBool(const std::string& v) {
  const std::string l = lower(v);
  if (l == "1" || l == "true" || l == "yes" || l == "on") return true;
  if (l == "0" || l == "false" || l == "no" || l == "off") return false;
  return std::nullopt;
}

std::optional<double> parseNumber(const std::string& v) {
  if (v.empty()) return std::nullopt;
  // strtod accepts "nan"/"inf": rejected below by the finite check.
  char* end = nullptr;
  const double d = std::strtod(v.c_str(), &end);
  if (end != v.c_str() + v.size() || !std::isfinite(d)) return std::nullopt;
  return d;
}

std::optional<uint32_t> parseCount(const std::string& v) {
  uint32_t out = 0;
  const auto [ptr, ec] = std::from_chars(v.data(), v.data() + v.size(), out);
  if (ec != std::errc() || ptr != v.data() + v.size()) return std::nullopt;
  return out;
}

// Float tunables of core::Params: key, member, accepted closed range.
struct FloatKey {
  const char* key;
  float core::Params::*member;
  float min;
  float max;
};
constexpr FloatKey kFloatKeys[] = {
    {"taa_alpha", &core::Params::taaAlpha, 0.0f, 1.0f},
    {"taa_clip_gamma", &core::Params::taaClipGamma, 0.0f, 10.0f},
    {"h_max", &core::Params::hMaxDegPerSec, 0.001f, 10000.0f},
    {"w_min", &core::Params::wMin, 0.0f, 1.0f},
    {"w_lb", &core::Params::wLowerBound, 0.0f, 1.0f},
    {"vtaa_alpha_min", &core::Params::vtaaAlphaMin, 0.0f, 1.0f},
    {"stereo_far_m", &core::Params::stereoFarDistanceM, 0.01f, 1.0e6f},
    {"stereo_depth_tolerance", &core::Params::stereoDepthTolerance, 0.0f, 1.0f},
    {"stereo_beta_min", &core::Params::stereoBetaMin, 0.0f, 1.0f},
    {"reset_angle_deg", &core::Params::resetAngleDeg, 0.0f, 180.0f},
    {"reset_translation_m", &core::Params::resetTranslationM, 0.0f, 100.0f},
    {"steady_alpha_floor", &core::Params::steadyAlphaFloor, 0.001f, 1.0f},
    {"steady_blur_budget_px2", &core::Params::steadyBlurBudgetPx2, 0.0f, 100.0f},
    {"steady_footprint", &core::Params::steadyFootprint, 0.0f, 0.25f},
    {"steady_nearest_depth_m", &core::Params::steadyNearestDepthM, 0.01f, 1.0e6f},
};

// Boolean switches of core::Params (steady's ablation switches).
struct BoolKey {
  const char* key;
  bool core::Params::*member;
};
constexpr BoolKey kBoolKeys[] = {
    {"steady_confidence", &core::Params::steadyConfidence},
    {"steady_clip_rejects", &core::Params::steadyClipRejects},
    {"steady_interpolated", &core::Params::steadyInterpolated},
};

constexpr const char* kOtherKeys[] = {"enabled",   "method",       "pose_source",   "imu_device",
                                      "log_level", "log_file",     "dump_frames",   "dump_dir",
                                      "jitter",    "sample_count", "history_filter"};

std::string formatFloat(float f) {
  std::ostringstream os;
  os << f;
  return os.str();
}

void bad(std::vector<std::string>* messages, const std::string& key, const std::string& value,
         const std::string& origin, const std::string& defaultText) {
  if (messages) {
    messages->push_back("config: bad value '" + value + "' for key '" + key + "' (" + origin +
                        "); using the default " + defaultText);
  }
}

// Applies one key; `origin` says where it came from, for the message.
void applyKey(Config& c, const std::string& key, const std::string& value, const std::string& origin,
              std::vector<std::string>* messages) {
  const Config defaults;
  if (key == "enabled") {
    if (auto b = parseBool(value))
      c.enabled = *b;
    else
      bad(messages, key, value, origin, "1");
  } else if (key == "method") {
    if (isKnownMethodName(lower(value)))
      c.method = lower(value);
    else
      bad(messages, key, value, origin, defaults.method);
  } else if (key == "pose_source") {
    const std::string l = lower(value);
    if (l == "runtime")
      c.poseSource = PoseSourceKind::Runtime;
    else if (l == "imu")
      c.poseSource = PoseSourceKind::Imu;
    else
      bad(messages, key, value, origin, "runtime");
  } else if (key == "imu_device") {
    if (!value.empty())
      c.imuDevice = value;
    else
      bad(messages, key, value, origin, defaults.imuDevice);
  } else if (key == "log_level") {
    const std::string l = lower(value);
    if (l == "error")
      c.logLevel = LogLevel::Error;
    else if (l == "warn" || l == "warning")
      c.logLevel = LogLevel::Warn;
    else if (l == "info")
      c.logLevel = LogLevel::Info;
    else if (l == "debug")
      c.logLevel = LogLevel::Debug;
    else
      bad(messages, key, value, origin, "info");
  } else if (key == "log_file") {
    c.logFile = value;
  } else if (key == "dump_frames") {
    if (auto n = parseCount(value); n && *n <= 100000)
      c.dumpFrames = *n;
    else
      bad(messages, key, value, origin, "0");
  } else if (key == "dump_dir") {
    if (!value.empty())
      c.dumpDir = value;
    else
      bad(messages, key, value, origin, defaults.dumpDir);
  } else if (key == "jitter") {
    if (auto b = parseBool(value))
      c.jitter = *b;
    else
      bad(messages, key, value, origin, "0");
  } else if (key == "history_filter") {
    const std::string l = lower(value);
    if (l == "bilinear")
      c.params.historyFilter = core::HistoryFilter::Bilinear;
    else if (l == "catmull-rom" || l == "catmullrom")
      c.params.historyFilter = core::HistoryFilter::CatmullRom;
    else
      bad(messages, key, value, origin, "bilinear");
  } else if (key == "sample_count") {
    if (auto n = parseCount(value); n && *n >= 1 && *n <= core::Params::kMaxSamples)
      c.params.sampleCount = *n;
    else
      bad(messages, key, value, origin, std::to_string(defaults.params.sampleCount));
  } else {
    for (const BoolKey& b : kBoolKeys) {
      if (key == b.key) {
        if (auto v = parseBool(value))
          c.params.*b.member = *v;
        else
          bad(messages, key, value, origin, defaults.params.*b.member ? "1" : "0");
        return;
      }
    }
    for (const FloatKey& f : kFloatKeys) {
      if (key == f.key) {
        const auto d = parseNumber(value);
        if (d && *d >= f.min && *d <= f.max)
          c.params.*f.member = static_cast<float>(*d);
        else
          bad(messages, key, value, origin, formatFloat(defaults.params.*f.member));
        return;
      }
    }
    if (messages) messages->push_back("config: unknown key '" + key + "' (" + origin + "); ignored");
  }
}

}  // namespace

std::string_view toString(LogLevel level) {
  switch (level) {
    case LogLevel::Error:
      return "error";
    case LogLevel::Warn:
      return "warn";
    case LogLevel::Info:
      return "info";
    case LogLevel::Debug:
      return "debug";
  }
  return "info";
}

bool isKnownMethodName(std::string_view name) {
  static constexpr std::string_view kTemporal[] = {"none", "fxaa",   "taa",   "hmtaa",
                                                   "vtaa", "hybrid", "steady"};
  if (name == "default" || name == "stereo") return true;
  std::string_view base = name;
  constexpr std::string_view kSuffix = "+stereo";
  if (base.size() > kSuffix.size() && base.substr(base.size() - kSuffix.size()) == kSuffix) {
    base = base.substr(0, base.size() - kSuffix.size());
  }
  return std::find(std::begin(kTemporal), std::end(kTemporal), base) != std::end(kTemporal);
}

std::vector<std::string> knownConfigKeys() {
  std::vector<std::string> keys(std::begin(kOtherKeys), std::end(kOtherKeys));
  for (const FloatKey& f : kFloatKeys) keys.emplace_back(f.key);
  for (const BoolKey& b : kBoolKeys) keys.emplace_back(b.key);
  return keys;
}

std::string envNameForKey(std::string_view key) {
  std::string out = "STEADYXR_";
  for (char ch : key) out += static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
  return out;
}

EnvLookup processEnvironment() {
  return [](const std::string& name) -> std::optional<std::string> {
    const char* v = std::getenv(name.c_str());
    if (v == nullptr) return std::nullopt;
    return std::string(v);
  };
}

ConfigText parseConfigText(std::string_view text, std::vector<std::string>* messages) {
  ConfigText out;
  std::map<std::string, std::string>* current = &out.global;
  size_t lineNo = 0;
  size_t pos = 0;
  while (pos <= text.size()) {
    const size_t nl = text.find('\n', pos);
    const std::string_view raw =
        text.substr(pos, nl == std::string_view::npos ? text.size() - pos : nl - pos);
    pos = (nl == std::string_view::npos) ? text.size() + 1 : nl + 1;
    ++lineNo;
    std::string line = trim(raw);
    if (line.empty() || line[0] == '#' || line[0] == ';') continue;
    if (line.front() == '[') {
      if (line.back() != ']' || line.size() < 3) {
        if (messages)
          messages->push_back("config: line " + std::to_string(lineNo) + ": malformed section header");
        continue;
      }
      current = &out.sections[trim(std::string_view(line).substr(1, line.size() - 2))];
      continue;
    }
    const size_t eq = line.find('=');
    if (eq == std::string::npos || trim(std::string_view(line).substr(0, eq)).empty()) {
      if (messages) messages->push_back("config: line " + std::to_string(lineNo) + ": expected key = value");
      continue;
    }
    std::string value = trim(std::string_view(line).substr(eq + 1));
    // Trailing comments, only when separated by whitespace ("a = b  # note").
    if (const size_t hash = value.find(" #"); hash != std::string::npos) value = trim(value.substr(0, hash));
    (*current)[lower(trim(std::string_view(line).substr(0, eq)))] = value;
  }
  return out;
}

std::optional<std::string> findConfigFile(const EnvLookup& env,
                                          const std::function<bool(const std::string&)>& exists) {
  if (auto p = env("STEADYXR_CONFIG"); p && !p->empty()) {
    return *p;  // named explicitly: used (and reported if unreadable) even when missing
  }
  if (exists("steadyxr.conf")) return std::string("steadyxr.conf");
  std::string base;
  if (auto x = env("XDG_CONFIG_HOME"); x && !x->empty()) {
    base = *x;
  } else if (auto h = env("HOME"); h && !h->empty()) {
    base = *h + "/.config";
  }
  if (!base.empty()) {
    const std::string p = base + "/steadyxr/steadyxr.conf";
    if (exists(p)) return p;
  }
  return std::nullopt;
}

Config resolveConfig(const ConfigText& text, std::string_view applicationName, const EnvLookup& env,
                     std::vector<std::string>* messages) {
  Config c;
  for (const auto& [k, v] : text.global) applyKey(c, k, v, "config file", messages);
  if (auto it = text.sections.find(std::string(applicationName)); it != text.sections.end()) {
    for (const auto& [k, v] : it->second) applyKey(c, k, v, "config section [" + it->first + "]", messages);
  }
  for (const std::string& key : knownConfigKeys()) {
    const std::string name = envNameForKey(key);
    if (auto v = env(name)) applyKey(c, key, trim(*v), "environment " + name, messages);
  }
  // A plain off switch that needs no value syntax.
  if (auto v = env("STEADYXR_DISABLE"); v && !v->empty() && *v != "0") c.enabled = false;
  return c;
}

Config loadConfig(std::string_view applicationName, const EnvLookup& env,
                  std::vector<std::string>* messages) {
  const auto exists = [](const std::string& p) {
    struct stat st {};
    return ::stat(p.c_str(), &st) == 0 && S_ISREG(st.st_mode);
  };
  ConfigText text;
  const std::optional<std::string> path = findConfigFile(env, exists);
  if (path) {
    std::ifstream in(*path);
    if (in) {
      std::stringstream ss;
      ss << in.rdbuf();
      text = parseConfigText(ss.str(), messages);
    } else if (messages) {
      messages->push_back("config: cannot read '" + *path + "'; using defaults and the environment");
    }
  }
  Config c = resolveConfig(text, applicationName, env, messages);
  if (path) c.configFile = *path;
  return c;
}

}  // namespace steadyxr::layer
