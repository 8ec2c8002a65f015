// Layer configuration: key=value file with per-application sections, overridden by environment
// variables. Pure functions (no global state) so that the unit tests can drive every path.
#pragma once

#include "steadyxr/core/params.h"

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
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
  bool jitter = false;     // inject a Halton sub-pixel jitter into xrLocateViews' fov
  std::string configFile;  // the file the values came from (empty: none)
};

// Raw key/value pairs of a config file: the global part and one map per [section].
struct ConfigText {
  std::map<std::string, std::string> global;
  std::map<std::string, std::map<std::string, std::string>> sections;
};

using EnvLookup = std::function<std::optional<std::string>(const std::string& name)>;
EnvLookup processEnvironment();

// Parses "key = value" lines, "# comments", "[application name]" sections. Malformed lines are
// reported in *messages and skipped.
ConfigText parseConfigText(std::string_view text, std::vector<std::string>* messages);

// The config file to read: $STEADYXR_CONFIG, else ./steadyxr.conf, else
// $XDG_CONFIG_HOME/steadyxr/steadyxr.conf (XDG_CONFIG_HOME defaults to $HOME/.config).
// `exists` is injectable for tests. Returns nullopt when none exists.
std::optional<std::string> findConfigFile(const EnvLookup& env,
                                          const std::function<bool(const std::string&)>& exists);

// Global values, then the section named after the application, then STEADYXR_<KEY> environment
// variables. Every bad value leaves the default and adds a message naming the key and default.
Config resolveConfig(const ConfigText& text, std::string_view applicationName, const EnvLookup& env,
                     std::vector<std::string>* messages);

// Whole pipeline for the layer: find, read, parse, resolve.
Config loadConfig(std::string_view applicationName, const EnvLookup& env, std::vector<std::string>* messages);

// Keys the resolver knows (tests, documentation).
std::vector<std::string> knownConfigKeys();
std::string envNameForKey(std::string_view key);  // "log_level" -> "STEADYXR_LOG_LEVEL"
bool isKnownMethodName(std::string_view name);
std::string_view toString(LogLevel level);

}  // namespace steadyxr::layer
