#include "config.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <locale>
#include <sstream>
#include <system_error>

namespace steadyxr::layer {
namespace {

// Keeps the first kMaxConfigMessages messages of the caller's list and counts the rest, which
// it reports in one line when it goes out of scope: 10^6 bad lines must not mean 10^6 warnings.
class MessageSink {
 public:
  explicit MessageSink(std::vector<std::string>* out) : out_(out) {}
  ~MessageSink() {
    if (out_ != nullptr && dropped_ > 0) {
      out_->push_back("config: " + std::to_string(dropped_) + " more problem" + (dropped_ == 1 ? "" : "s") +
                      " not shown");
    }
  }
  MessageSink(const MessageSink&) = delete;
  MessageSink& operator=(const MessageSink&) = delete;
  // `make` builds the text only when it is kept.
  template <typename F>
  void add(F&& make) {
    ++total_;
    if (out_ == nullptr) return;
    if (out_->size() < kMaxConfigMessages) {
      out_->push_back(make());
    } else {
      ++dropped_;
    }
  }
  size_t total() const { return total_; }

 private:
  std::vector<std::string>* out_;
  size_t dropped_ = 0;
  size_t total_ = 0;
};

std::optional<bool> parseBool(const std::string& v) {
  const std::string l = lower(v);
  if (l == "1" || l == "true" || l == "yes" || l == "on") return true;
  if (l == "0" || l == "false" || l == "no" || l == "off") return false;
  return std::nullopt;
}

// Decimal only and independent of the locale (std::from_chars): "0x10", "1,5", "nan" and
// "inf" are not numbers here.
std::optional<double> parseNumber(const std::string& v) {
  if (v.empty()) return std::nullopt;
  double d = 0.0;
  const auto [ptr, ec] = std::from_chars(v.data(), v.data() + v.size(), d, std::chars_format::general);
  if (ec != std::errc() || ptr != v.data() + v.size() || !std::isfinite(d)) return std::nullopt;
  return d;
}

std::optional<uint32_t> parseCount(const std::string& v) {
  uint32_t out = 0;
  const auto [ptr, ec] = std::from_chars(v.data(), v.data() + v.size(), out);
  if (v.empty() || ec != std::errc() || ptr != v.data() + v.size()) return std::nullopt;
  return out;
}

// Float tunables of core::Params: key, member, accepted range. The ranges are those
// core::validate accepts (strict where it needs a positive value), so that a value the config
// takes never reaches the core as invalid.
struct FloatKey {
  const char* key;
  float core::Params::*member;
  float min;
  float max;
  bool minExclusive;
};
constexpr FloatKey kFloatKeys[] = {
    {"taa_alpha", &core::Params::taaAlpha, 0.0f, 1.0f, true},
    {"taa_clip_gamma", &core::Params::taaClipGamma, 0.0f, 10.0f, true},
    {"h_max", &core::Params::hMaxDegPerSec, 0.001f, 10000.0f, false},
    {"w_min", &core::Params::wMin, 0.0f, 1.0f, false},
    {"w_lb", &core::Params::wLowerBound, 0.0f, 1.0f, false},
    {"vtaa_alpha_min", &core::Params::vtaaAlphaMin, 0.0f, 1.0f, false},
    {"stereo_far_m", &core::Params::stereoFarDistanceM, 0.01f, 1.0e6f, false},
    {"stereo_depth_tolerance", &core::Params::stereoDepthTolerance, 0.0f, 1.0f, false},
    {"stereo_beta_min", &core::Params::stereoBetaMin, 0.0f, 1.0f, false},
    {"reset_angle_deg", &core::Params::resetAngleDeg, 0.0f, 180.0f, true},
    {"reset_translation_m", &core::Params::resetTranslationM, 0.0f, 100.0f, true},
    {"steady_alpha_floor", &core::Params::steadyAlphaFloor, 0.001f, 1.0f, false},
    {"steady_blur_budget_px2", &core::Params::steadyBlurBudgetPx2, 0.0f, 100.0f, false},
    {"steady_footprint", &core::Params::steadyFootprint, 0.0f, 0.25f, false},
    {"steady_clip_gamma", &core::Params::steadyClipGamma, 0.0f, 1000.0f, true},
    {"steady_output_hold", &core::Params::steadyOutputHold, 0.0f, 0.5f, false},
    {"steady_nearest_depth_m", &core::Params::steadyNearestDepthM, 0.01f, 1.0e6f, false},
    {"stereo_clip_gamma_after_steady", &core::Params::stereoClipGammaAfterSteady, 0.0f, 1000.0f, true},
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
    {"steady_footprint_encoded", &core::Params::steadyFootprintEncoded},
    {"steady_history_blur_per_axis", &core::Params::steadyHistoryBlurPerAxis},
    {"steady_blur_noise_trade", &core::Params::steadyBlurNoiseTrade},
    {"steady_clip_holds_current", &core::Params::steadyClipHoldsCurrent},
    {"steady_clip_curvature", &core::Params::steadyClipCurvature},
    {"steady_clip_curvature_centred", &core::Params::steadyClipCurvatureCentred},
    {"steady_clip_curvature_centred_gated", &core::Params::steadyClipCurvatureCentredGated},
    {"steady_clip_quant_srgb", &core::Params::steadyClipQuantSrgb},
    {"steady_noise_estimate", &core::Params::steadyNoiseEstimate},
    {"steady_noise_residual_over_time", &core::Params::steadyNoiseResidualOverTime},
    {"steady_noise_change_test", &core::Params::steadyNoiseChangeTest},
    {"steady_gain_compensation", &core::Params::steadyGainCompensation},
    {"steady_gain_relights_admitted", &core::Params::steadyGainRelightsAdmitted},
    {"steady_unexplained_frame_resets", &core::Params::steadyUnexplainedFrameResets},
    {"steady_resolved_edges", &core::Params::steadyResolvedEdges},
    {"steady_head_locked_switch", &core::Params::steadyHeadLockedSwitch},
    {"stereo_inverse_variance", &core::Params::stereoInverseVariance},
    {"stereo_tap_curvature", &core::Params::stereoTapCurvature},
};

constexpr const char* kOtherKeys[] = {
    "enabled",  "method", "pose_source",  "imu_device",     "log_level",      "log_file", "dump_frames",
    "dump_dir", "jitter", "sample_count", "history_filter", "history_format", "profile"};

// Profiles: settings measured for a kind of app (README: "Profiles for kinds of app").
// hud: an app that draws head-locked content (a HUD, a reticle) into its eye images. A sixteenth
// of the blur budget (1/96 px^2) and the box reaching the pixel's own estimate keep the ring
// around the overlay below none's (issue 14 round 11: 2 of 132 HUD cases above, by 0.3 %).
constexpr ProfileSetting kHudProfile[] = {{"steady_blur_budget_px2", "0.0104"},
                                          {"steady_clip_holds_current", "1"}};
// world-only: an app whose eye images hold world content only (no video, no HUD): round 10's gate
// on the one-sided box (fresh static draws 0.744 and 0.735 of none's against 0.791 and 0.789).
// Round 42: such an app needs no head-locked switch either.
constexpr ProfileSetting kWorldOnlyProfile[] = {{"steady_clip_curvature_centred_gated", "1"},
                                                {"steady_head_locked_switch", "0"}};
// noisy: an app whose eye images carry per-frame noise (film grain, a path tracer, dithered
// transparency): the render's noise estimated and the clip box widened by it. Rounds 13-14's option;
// the default since round 15, so the profile sets what the default has (a config that names it keeps
// working, and it turns the estimate back on over a global steady_noise_estimate = 0).
constexpr ProfileSetting kNoisyProfile[] = {{"steady_noise_estimate", "1"}};
constexpr const char* kProfileText = "default, hud, world-only or noisy";

std::string formatFloat(float f) {
  std::ostringstream os;
  os.imbue(std::locale::classic());
  os << f;
  return os.str();
}

// Where a value came from, in the user's words: the line they wrote or the variable they set.
struct Origin {
  std::string where;  // "config file", "config section [app]", "environment"
  std::string name;   // what the user wrote: the key, or the variable's name
};

// "w_lb = abc (config file): expected a number in [0, 1]; using the default 0.1"
void bad(MessageSink& sink, const Origin& origin, const std::string& value, const std::string& expected,
         const std::string& defaultText) {
  sink.add([&] {
    return "config: " + origin.name + " = " + value + " (" + origin.where + "): expected " + expected +
           "; using the default " + defaultText;
  });
}

std::string rangeText(const FloatKey& f) {
  return std::string("a number in ") + (f.minExclusive ? "(" : "[") + formatFloat(f.min) + ", " +
         formatFloat(f.max) + "]";
}

constexpr const char* kBoolText = "1/0, true/false, yes/no or on/off";
constexpr const char* kMethodText =
    "none, fxaa, taa, hmtaa, vtaa, hybrid, steady, stereo, <one of these>+stereo or default";

// Applies one key.
void applyKey(Config& c, const std::string& key, const std::string& value, const Origin& origin,
              MessageSink& sink) {
  const Config defaults;
  if (key == "enabled") {
    if (auto b = parseBool(value))
      c.enabled = *b;
    else
      bad(sink, origin, value, kBoolText, "1");
  } else if (key == "method") {
    if (isKnownMethodName(lower(value)))
      c.method = lower(value);
    else
      bad(sink, origin, value, kMethodText, defaults.method);
  } else if (key == "pose_source") {
    const std::string l = lower(value);
    if (l == "runtime")
      c.poseSource = PoseSourceKind::Runtime;
    else if (l == "imu")
      c.poseSource = PoseSourceKind::Imu;
    else
      bad(sink, origin, value, "runtime or imu", "runtime");
  } else if (key == "imu_device") {
    if (!value.empty())
      c.imuDevice = value;
    else
      bad(sink, origin, value, "a device spec", defaults.imuDevice);
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
      bad(sink, origin, value, "error, warn, info or debug", "info");
  } else if (key == "log_file") {
    c.logFile = value;
  } else if (key == "dump_frames") {
    if (auto n = parseCount(value); n && *n <= 100000)
      c.dumpFrames = *n;
    else
      bad(sink, origin, value, "a whole number in [0, 100000]", "0");
  } else if (key == "dump_dir") {
    if (!value.empty())
      c.dumpDir = value;
    else
      bad(sink, origin, value, "a folder", defaults.dumpDir);
  } else if (key == "jitter") {
    if (auto b = parseBool(value))
      c.jitter = *b;
    else
      bad(sink, origin, value, kBoolText, "0");
  } else if (key == "history_filter") {
    const std::string l = lower(value);
    if (l == "bilinear")
      c.params.historyFilter = core::HistoryFilter::Bilinear;
    else if (l == "catmull-rom" || l == "catmullrom")
      c.params.historyFilter = core::HistoryFilter::CatmullRom;
    else
      bad(sink, origin, value, "bilinear or catmull-rom", "bilinear");
  } else if (key == "history_format") {
    const std::string l = lower(value);
    if (l == "rgba16f")
      c.params.historyFormat = core::HistoryFormat::Rgba16f;
    else if (l == "rgba8")
      c.params.historyFormat = core::HistoryFormat::Rgba8Dithered;
    else
      bad(sink, origin, value, "rgba16f or rgba8",
          defaults.params.historyFormat == core::HistoryFormat::Rgba16f ? "rgba16f" : "rgba8");
  } else if (key == "profile") {  // its settings are applied first, by resolveConfig
    if (profileSettings(lower(value))) {
      c.profile = lower(value);
    } else {
      c.profile = defaults.profile;  // as resolveConfig applied no profile's settings
      bad(sink, origin, value, kProfileText, defaults.profile);
    }
  } else if (key == "sample_count") {
    if (auto n = parseCount(value); n && *n >= 1 && *n <= core::Params::kMaxSamples)
      c.params.sampleCount = *n;
    else
      bad(sink, origin, value, "a whole number in [1, " + std::to_string(core::Params::kMaxSamples) + "]",
          std::to_string(defaults.params.sampleCount));
  } else {
    for (const BoolKey& b : kBoolKeys) {
      if (key == b.key) {
        if (auto v = parseBool(value))
          c.params.*b.member = *v;
        else
          bad(sink, origin, value, kBoolText, defaults.params.*b.member ? "1" : "0");
        return;
      }
    }
    for (const FloatKey& f : kFloatKeys) {
      if (key == f.key) {
        const auto d = parseNumber(value);
        if (d && (f.minExclusive ? *d > f.min : *d >= f.min) && *d <= f.max)
          c.params.*f.member = static_cast<float>(*d);
        else
          bad(sink, origin, value, rangeText(f), formatFloat(defaults.params.*f.member));
        return;
      }
    }
    sink.add([&] { return "config: unknown key '" + origin.name + "' (" + origin.where + "); ignored"; });
  }
}

// Seed 003's Eq. 5 lowers w_min towards w_lb: w_lb above w_min has no meaning (the core would
// replace it). Said here in the user's keys, not the core's field names.
void checkWeights(Config& c, MessageSink& sink) {
  if (c.params.wLowerBound <= c.params.wMin) return;
  sink.add([&] {
    return "config: w_lb = " + formatFloat(c.params.wLowerBound) +
           " is above w_min = " + formatFloat(c.params.wMin) +
           " (w_lb must not exceed w_min); using w_lb = " + formatFloat(c.params.wMin);
  });
  c.params.wLowerBound = c.params.wMin;
}

}  // namespace

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
  MessageSink sink(messages);
  ConfigText out;
  std::map<std::string, std::string>* current = &out.global;
  std::string currentName;  // section name; empty: the global part
  // Line of each key's last setting, per part, to warn about duplicates.
  std::map<std::string, std::map<std::string, size_t>> keyLines;
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
        sink.add([&] { return "config: line " + std::to_string(lineNo) + ": malformed section header"; });
        continue;
      }
      currentName = trim(std::string_view(line).substr(1, line.size() - 2));
      current = &out.sections[currentName];
      continue;
    }
    const size_t eq = line.find('=');
    if (eq == std::string::npos || trim(std::string_view(line).substr(0, eq)).empty()) {
      sink.add([&] { return "config: line " + std::to_string(lineNo) + ": expected key = value"; });
      continue;
    }
    std::string value = trim(std::string_view(line).substr(eq + 1));
    // Trailing comments, only when separated by whitespace ("a = b  # note").
    if (const size_t hash = value.find(" #"); hash != std::string::npos) value = trim(value.substr(0, hash));
    const std::string key = lower(trim(std::string_view(line).substr(0, eq)));
    size_t& firstLine = keyLines[currentName][key];
    if (firstLine != 0) {
      sink.add([&] {
        return "config: line " + std::to_string(lineNo) + ": " + key + " is set again" +
               (currentName.empty() ? "" : " in [" + currentName + "]") + " (also on line " +
               std::to_string(firstLine) + "); the later value '" + value + "' wins";
      });
    }
    firstLine = lineNo;
    (*current)[key] = value;
  }
  return out;
}

std::optional<std::string> findConfigFile(const EnvLookup& env,
                                          const std::function<bool(const std::string&)>& exists) {
  if (auto p = env("STEADYXR_CONFIG"); p && !p->empty()) {
    return *p;  // named explicitly: used (and reported if unreadable) even when missing
  }
  if (exists("steadyxr.conf")) return std::string("steadyxr.conf");
  if (std::string p = userConfigPath(env); !p.empty() && exists(p)) return p;
  return std::nullopt;
}

std::string userConfigPath(const EnvLookup& env) {
  std::string base;
  if (auto x = env("XDG_CONFIG_HOME"); x && !x->empty()) {
    base = *x;
  } else if (auto h = env("HOME"); h && !h->empty()) {
    base = *h + "/.config";
  }
  return base.empty() ? std::string() : base + "/steadyxr/steadyxr.conf";
}

std::optional<std::span<const ProfileSetting>> profileSettings(std::string_view name) {
  if (name == "default") return std::span<const ProfileSetting>{};
  if (name == "hud") return kHudProfile;
  if (name == "world-only") return kWorldOnlyProfile;
  if (name == "noisy") return kNoisyProfile;
  return std::nullopt;
}

Config resolveConfig(const ConfigText& text, std::string_view applicationName, const EnvLookup& env,
                     std::vector<std::string>* messages) {
  MessageSink sink(messages);
  Config c;
  // Three places, least specific first: the file's global part, the app's section, the environment.
  // The profile named in the most specific place counts as set there: its settings win over keys
  // of less specific places and lose to keys of the same or a more specific place. A bad name is
  // reported with the other keys and means no profile.
  const auto section = text.sections.find(std::string(applicationName));
  const bool hasSection = section != text.sections.end();
  std::map<std::string, std::string> environment;
  for (const std::string& key : knownConfigKeys()) {
    if (auto v = env(envNameForKey(key))) environment[key] = trim(*v);
  }
  const std::map<std::string, std::string> noKeys;
  struct Place {
    const std::map<std::string, std::string>& keys;
    std::string where;
  };
  const std::array<Place, 3> places{
      {{text.global, "config file"},
       {hasSection ? section->second : noKeys, hasSection ? "config section [" + section->first + "]" : ""},
       {environment, "environment"}}};
  size_t profilePlace = places.size();
  std::string profile;
  for (size_t i = 0; i < places.size(); ++i) {
    if (auto it = places[i].keys.find("profile"); it != places[i].keys.end()) {
      profilePlace = i;
      profile = lower(it->second);
    }
  }
  for (size_t i = 0; i < places.size(); ++i) {
    if (i == profilePlace) {
      MessageSink silent(nullptr);  // a profile's own values are valid (a test checks each)
      for (const ProfileSetting& p : profileSettings(profile).value_or(std::span<const ProfileSetting>{}))
        applyKey(c, p.key, p.value, {"profile " + profile, p.key}, silent);
    }
    const bool fromEnvironment = &places[i].keys == &environment;
    for (const auto& [k, v] : places[i].keys) {
      applyKey(c, k, v, {places[i].where, fromEnvironment ? envNameForKey(k) : k}, sink);
      if (fromEnvironment && k == "enabled" && !c.enabled) c.environmentDisabled = true;
    }
  }
  // A plain off switch that needs no value syntax.
  if (auto v = env("STEADYXR_DISABLE"); v && !v->empty() && *v != "0") {
    c.enabled = false;
    c.environmentDisabled = true;
  }
  checkWeights(c, sink);
  return c;
}

std::optional<std::string> readConfigFile(const std::string& path, std::string* error) {
  const auto fail = [&](const std::string& why) -> std::optional<std::string> {
    if (error) *error = "config: '" + path + "' " + why;
    return std::nullopt;
  };
  // O_NONBLOCK: opening a FIFO must not wait for a writer (it is rejected below anyway).
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOCTTY | O_NONBLOCK);
  if (fd < 0) return fail("cannot be opened (" + std::generic_category().message(errno) + ")");
  struct FdCloser {
    int fd;
    ~FdCloser() { ::close(fd); }
  } closer{fd};
  struct stat st {};
  if (::fstat(fd, &st) != 0) return fail("cannot be read (" + std::generic_category().message(errno) + ")");
  if (!S_ISREG(st.st_mode)) {
    return fail(std::string("is not a regular file (") +
                (S_ISDIR(st.st_mode) ? "a directory" : "a device, pipe or socket") + ")");
  }
  const std::string tooBig = "is larger than the limit of " + std::to_string(kMaxConfigBytes) + " bytes";
  if (static_cast<uint64_t>(st.st_size) > kMaxConfigBytes) return fail(tooBig);
  // Reads until the end or one byte past the limit (the file may grow while it is read).
  std::string text;
  size_t got = 0;
  while (got <= kMaxConfigBytes) {
    text.resize(std::min(got + 65536, kMaxConfigBytes + 1));
    const ssize_t n = ::read(fd, text.data() + got, text.size() - got);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return fail("cannot be read (" + std::generic_category().message(errno) + ")");
    if (n == 0) break;
    got += static_cast<size_t>(n);
  }
  if (got > kMaxConfigBytes) return fail(tooBig);
  text.resize(got);
  return text;
}

Config loadConfig(std::string_view applicationName, const EnvLookup& env,
                  std::vector<std::string>* messages) {
  const auto exists = [](const std::string& p) {
    struct stat st {};
    return ::stat(p.c_str(), &st) == 0 && S_ISREG(st.st_mode);
  };
  ConfigText text;
  const std::optional<std::string> path = findConfigFile(env, exists);
  bool read = false;
  if (path) {
    std::string error;
    if (std::optional<std::string> content = readConfigFile(*path, &error)) {
      text = parseConfigText(*content, messages);
      read = true;
    } else if (messages) {
      messages->push_back(error + "; using defaults and the environment");
    }
  }
  Config c = resolveConfig(text, applicationName, env, messages);
  if (read) c.configFile = *path;
  return c;
}

std::map<std::string, std::string> effectiveSettings(const ConfigText& text, std::string_view applicationName,
                                                     const EnvLookup& env) {
  std::map<std::string, std::string> out = text.global;
  if (auto it = text.sections.find(std::string(applicationName)); it != text.sections.end()) {
    for (const auto& [k, v] : it->second) out[k] = v;
  }
  for (const std::string& key : knownConfigKeys()) {
    if (auto v = env(envNameForKey(key))) out[key] = trim(*v);
  }
  return out;
}

std::optional<Config> reloadConfig(const std::string& path, std::string_view applicationName,
                                   const EnvLookup& env, std::vector<std::string>* messages,
                                   std::map<std::string, std::string>* settings) {
  std::string error;
  const std::optional<std::string> content = readConfigFile(path, &error);
  if (!content) {
    if (messages) messages->push_back(error);
    return std::nullopt;
  }
  // Problems of the file alone decide (a bad environment variable was reported at start-up and
  // must not block every later edit).
  std::vector<std::string> problems;
  const ConfigText text = parseConfigText(*content, &problems);
  const auto noEnvironment = [](const std::string&) -> std::optional<std::string> { return std::nullopt; };
  resolveConfig(text, applicationName, noEnvironment, &problems);
  if (!problems.empty()) {
    if (messages) messages->insert(messages->end(), problems.begin(), problems.end());
    return std::nullopt;
  }
  Config c = resolveConfig(text, applicationName, env, nullptr);
  c.configFile = path;
  if (settings) *settings = effectiveSettings(text, applicationName, env);
  return c;
}

std::string checkSetting(std::string_view key, std::string_view value) {
  std::vector<std::string> messages;
  {
    MessageSink sink(&messages);
    Config c;
    const std::string k = lower(trim(key));
    applyKey(c, k, trim(value), {"command line", k}, sink);
  }
  return messages.empty() ? std::string() : messages.front();
}

}  // namespace steadyxr::layer
