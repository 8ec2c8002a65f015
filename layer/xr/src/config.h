// Layer configuration: key=value file with per-application sections, overridden by environment
// variables. Pure functions (no global state) so that the unit tests can drive every path.
#pragma once

#include "steadyxr/core/params.h"

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace steadyxr::layer {

enum class LogLevel : uint8_t { Error, Warn, Info, Debug };
enum class PoseSourceKind : uint8_t { Runtime, Imu };

struct Config {
  bool enabled = true;
  std::string method = "default";  // a name core::applyMethodName accepts
  core::Params params;             // tunables; method fields are set from `method` by the layer
  PoseSourceKind poseSource = PoseSourceKind::Runtime;
  std::string imuDevice = "auto";  // "auto", a /dev/hidrawN path, "VID:PID" (hex), or "pipe:<path>"
  LogLevel logLevel = LogLevel::Info;
  std::string logFile;      // empty: standard error
  uint32_t dumpFrames = 0;  // first N frames' input and output eye images as PNG
  std::string dumpDir = "steadyxr-dump";
  bool jitter = false;  // inject a Halton sub-pixel jitter into xrLocateViews' fov
  // A named set of pass settings for a kind of app (`profile = hud`; profileSettings), applied
  // where it is named (resolveConfig).
  std::string profile = "default";
  std::string configFile;  // the file the values came from (empty: none)
  // STEADYXR_ENABLED=0 or STEADYXR_DISABLE in the environment: the layer hooks nothing for the
  // whole process (no live switching). `enabled = 0` in the file only passes frames through,
  // so that the file can switch filtering back on while the app runs.
  bool environmentDisabled = false;
};

// Limits on what the layer reads: a config is a few lines, and the layer is a guest in the
// app's process (an unbounded read of /dev/zero grew an app to 2 GB).
inline constexpr size_t kMaxConfigBytes = size_t{1} << 20;  // 1 MiB
inline constexpr size_t kMaxConfigMessages = 10;            // then one line with the count

// Reads a config file: regular files only, at most kMaxConfigBytes. Never blocks on a FIFO or
// device. On failure returns nullopt and a message in *error.
std::optional<std::string> readConfigFile(const std::string& path, std::string* error);

// Raw key/value pairs of a config file: the global part and one map per [section].
struct ConfigText {
  std::map<std::string, std::string> global;
  std::map<std::string, std::map<std::string, std::string>> sections;
};

using EnvLookup = std::function<std::optional<std::string>(const std::string& name)>;
EnvLookup processEnvironment();

// The parser's own text rules, shared with the `steadyxr` tool so both read a line the same way:
// ASCII white space trimmed at both ends; keys compared in ASCII lower case.
std::string trim(std::string_view s);
std::string lower(std::string s);

// Parses "key = value" lines, "# comments", "[application name]" sections. Malformed lines are
// reported in *messages and skipped.
ConfigText parseConfigText(std::string_view text, std::vector<std::string>* messages);

// The config file to read: $STEADYXR_CONFIG, else ./steadyxr.conf, else
// $XDG_CONFIG_HOME/steadyxr/steadyxr.conf (XDG_CONFIG_HOME defaults to $HOME/.config).
// `exists` is injectable for tests. Returns nullopt when none exists.
std::optional<std::string> findConfigFile(const EnvLookup& env,
                                          const std::function<bool(const std::string&)>& exists);

// The keys and values a profile sets ("default": none); nullopt for a name that is no profile.
struct ProfileSetting {
  const char* key;
  const char* value;
};
std::optional<std::span<const ProfileSetting>> profileSettings(std::string_view name);

// Global values, then the section named after the application, then STEADYXR_<KEY> environment
// variables. The profile named in the most specific of the three counts as set there: its
// settings go before that place's keys. Every bad value leaves the default and adds a message
// naming the key and default.
Config resolveConfig(const ConfigText& text, std::string_view applicationName, const EnvLookup& env,
                     std::vector<std::string>* messages);

// Whole pipeline for the layer: find, read, parse, resolve.
Config loadConfig(std::string_view applicationName, const EnvLookup& env, std::vector<std::string>* messages);

// Reads and resolves `path` for a live reload. Returns nullopt when the file cannot be read or
// has any problem (a bad value, an unknown key, a malformed line): a bad edit must not replace
// good settings. *messages says why.
std::optional<Config> reloadConfig(const std::string& path, std::string_view applicationName,
                                   const EnvLookup& env, std::vector<std::string>* messages,
                                   std::map<std::string, std::string>* settings = nullptr);

// The settings in effect for an application as the user wrote them (key -> value): the global
// part, then its section, then STEADYXR_<KEY> variables. What changed between two of these is
// what a live reload reports and applies, key by key, whatever keys the core grows.
std::map<std::string, std::string> effectiveSettings(const ConfigText& text, std::string_view applicationName,
                                                     const EnvLookup& env);

// The per-user config file, whether or not it exists: $XDG_CONFIG_HOME/steadyxr/steadyxr.conf,
// else $HOME/.config/steadyxr/steadyxr.conf. Empty when neither variable is set.
std::string userConfigPath(const EnvLookup& env);

// Checks one setting as the layer would read it. Returns an empty string when it is good, else
// the message the layer would log.
std::string checkSetting(std::string_view key, std::string_view value);

// Keys the resolver knows (tests, documentation).
std::vector<std::string> knownConfigKeys();
std::string envNameForKey(std::string_view key);  // "log_level" -> "STEADYXR_LOG_LEVEL"
bool isKnownMethodName(std::string_view name);
std::string_view toString(LogLevel level);

}  // namespace steadyxr::layer
