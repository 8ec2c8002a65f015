#include "cli.h"

#include "status_file.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <system_error>

namespace steadyxr::cli {
namespace {

namespace fs = std::filesystem;
using layer::lower;
using layer::trim;

constexpr const char* kUsage = R"(usage: steadyxr [--config FILE] COMMAND [ARGS]

Edits the steadyxr layer's per-user config and shows the running instances. Layers that run
notice the edit within a frame or two (enabled, method, pass parameters, dump_frames/dump_dir);
the other keys apply at the app's next start.

commands:
  enable  [--app NAME]              filtering on (enabled = 1)
  disable [--app NAME]              filtering off: frames pass through (enabled = 0)
  set     [--app NAME] KEY=VALUE... set keys, e.g. `set method=taa`, `set --app hello_xr method=none`
  unset   [--app NAME] KEY...       remove keys (back to the default or the global value)
  show    [--app NAME]              the config file, its problems and the settings in effect
  status                            the running layer instances (their status files)
  help, --help                      this text

--app NAME edits the [NAME] section: the app's XrApplicationInfo::applicationName (`steadyxr
status` shows it), which wins over the global settings for that app.

config file: --config FILE, else $STEADYXR_CONFIG, else $XDG_CONFIG_HOME/steadyxr/steadyxr.conf
(~/.config/steadyxr/steadyxr.conf). The file is replaced atomically; a bad key or value is
refused with the layer's own message and the file is left untouched. STEADYXR_<KEY>
environment variables of an app win over the file.

keys: enabled, method (none, fxaa, taa, hmtaa, vtaa, hybrid, stereo, <temporal>+stereo,
default), pose_source, imu_device, log_level, log_file, dump_frames, dump_dir, jitter,
taa_alpha, taa_clip_gamma, h_max, w_min, w_lb, sample_count, vtaa_alpha_min, stereo_far_m,
stereo_depth_tolerance, stereo_beta_min, reset_angle_deg, reset_translation_m, history_filter,
history_format, profile, and the steady_* and stereo_* pass keys (layer/xr/README.md).

profiles (`set --app NAME profile=hud`; a key set in the same or a more specific place wins):
  hud         the app draws head-locked content (a HUD, a reticle) into its eye images
  world-only  the app's eye images hold world content only: no video, no HUD (more accuracy)
  noisy       the app's eye images carry per-frame noise (the default's noise estimate, on)
  default     no profile (README: "Profiles for kinds of app")

exit status: 0 done, 1 error (config untouched), 2 usage error.
)";

std::vector<std::string> splitLines(std::string_view text) {
  std::vector<std::string> lines;
  size_t pos = 0;
  while (pos < text.size()) {
    const size_t nl = text.find('\n', pos);
    if (nl == std::string_view::npos) {
      lines.emplace_back(text.substr(pos));
      break;
    }
    lines.emplace_back(text.substr(pos, nl - pos));
    pos = nl + 1;
  }
  return lines;
}

std::string joinLines(const std::vector<std::string>& lines) {
  std::string out;
  for (const std::string& l : lines) out += l + "\n";
  return out;
}

// The section a line opens, parsed as layer::parseConfigText does; nullopt for other lines.
std::optional<std::string> sectionOf(const std::string& rawLine) {
  const std::string line = trim(rawLine);
  if (line.size() < 3 || line.front() != '[' || line.back() != ']') return std::nullopt;
  return trim(std::string_view(line).substr(1, line.size() - 2));
}

// The key a line sets, as the parser reads it; nullopt for comments, headers and other lines.
std::optional<std::string> keyOf(const std::string& rawLine) {
  const std::string line = trim(rawLine);
  if (line.empty() || line[0] == '#' || line[0] == ';' || line[0] == '[') return std::nullopt;
  const size_t eq = line.find('=');
  if (eq == std::string::npos) return std::nullopt;
  std::string key = lower(trim(std::string_view(line).substr(0, eq)));
  if (key.empty()) return std::nullopt;
  return key;
}

struct Part {
  std::vector<size_t> keyLines;  // lines that set the key, in order
  std::optional<size_t> header;  // the section header (none for the global part)
  std::optional<size_t> lastSetting;
  std::optional<size_t> firstSectionHeader;  // of the whole file: where the global part ends
};

Part findPart(const std::vector<std::string>& lines, const std::string& section, const std::string& key) {
  Part part;
  std::optional<std::string> current;  // nullopt: the global part
  for (size_t i = 0; i < lines.size(); ++i) {
    if (auto s = sectionOf(lines[i])) {
      current = *s;
      if (!part.firstSectionHeader) part.firstSectionHeader = i;
      if (!section.empty() && *s == section) part.header = i;
      continue;
    }
    const bool inPart = section.empty() ? !current.has_value() : current == section;
    if (!inPart) continue;
    if (auto k = keyOf(lines[i])) {
      part.lastSetting = i;
      if (*k == key) part.keyLines.push_back(i);
    }
  }
  return part;
}

// "key = value", keeping a trailing " # comment" of the line it replaces.
std::string settingLine(const std::string& key, const std::string& value, const std::string& replaced) {
  std::string line = key + " = " + value;
  const size_t eq = replaced.find('=');
  const size_t hash = eq == std::string::npos ? std::string::npos : replaced.find(" #", eq);
  if (hash != std::string::npos) line += "  " + trim(std::string_view(replaced).substr(hash));
  return line;
}

std::string configPath(const std::optional<std::string>& option, const layer::EnvLookup& env) {
  if (option) return *option;
  if (auto p = env("STEADYXR_CONFIG"); p && !p->empty()) return *p;
  return layer::userConfigPath(env);
}

// Problems the layer would report for the settings of `section` (empty: apps without one).
std::vector<std::string> problemsFor(const std::string& text, const std::string& section) {
  std::vector<std::string> problems;
  const layer::ConfigText parsed = layer::parseConfigText(text, &problems);
  const auto noEnvironment = [](const std::string&) -> std::optional<std::string> { return std::nullopt; };
  layer::resolveConfig(parsed, section, noEnvironment, &problems);
  return problems;
}

// A layer message as the CLI's answer: "w_lb = abc (command line): expected ..." without the
// layer's "config: " prefix and without what the layer would do instead (the CLI refuses).
std::string forCommandLine(std::string message) {
  if (message.starts_with("config: ")) message.erase(0, 8);
  for (const char* tail : {"; using the default", "; ignored"}) {
    if (const size_t at = message.find(tail); at != std::string::npos) message.erase(at);
  }
  return message;
}

struct Edit {
  std::string path;
  std::string before;
  bool existed = false;
};

// Reads the file to edit with the layer's own limits. False (message printed) on failure.
bool readForEdit(const std::string& path, Edit* edit, std::ostream& err) {
  edit->path = path;
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(path, ec)) || (fs::is_symlink(path, ec) && !fs::exists(path, ec))) {
    edit->existed = false;
    return true;
  }
  std::string error;
  std::optional<std::string> text = layer::readConfigFile(path, &error);
  if (!text) {
    err << "steadyxr: " << error << "; not changed\n";
    return false;
  }
  edit->before = std::move(*text);
  edit->existed = true;
  return true;
}

bool validAppName(const std::string& app, std::ostream& err) {
  if (app.empty() || app != trim(app) || app.find_first_of("\n\r") != std::string::npos) {
    err << "steadyxr: bad app name '" << app
        << "': it must be the app's XrApplicationInfo::applicationName, without line breaks or "
           "surrounding spaces\n";
    return false;
  }
  return true;
}

// Checks the new text against the old, writes it, and reports. The file stays as it was on any
// problem.
int commit(const Edit& edit, const std::string& after, const std::string& section, const std::string& what,
           std::ostream& out, std::ostream& err) {
  const std::vector<std::string> oldProblems = problemsFor(edit.before, section);
  const std::vector<std::string> newProblems = problemsFor(after, section);
  if (newProblems.size() > oldProblems.size()) {
    for (const std::string& p : newProblems) err << "steadyxr: " << forCommandLine(p) << "\n";
    err << "steadyxr: " << edit.path << " not changed\n";
    return 1;
  }
  if (!oldProblems.empty()) {
    err << "steadyxr: note: " << edit.path << " already had problems (see `steadyxr show`):\n";
    for (const std::string& p : oldProblems) err << "  " << p << "\n";
  }
  if (after == edit.before && edit.existed) {
    out << what << " (already so in " << edit.path << ")\n";
    return 0;
  }
  std::string error;
  if (!writeFileAtomically(edit.path, after, &error)) {
    err << "steadyxr: " << error << "; " << edit.path << " not changed\n";
    return 1;
  }
  out << what << " in " << edit.path << "\n";
  return 0;
}

int setKeys(const std::vector<std::pair<std::string, std::string>>& settings, const std::string& app,
            const std::string& path, std::ostream& out, std::ostream& err) {
  for (const auto& [key, value] : settings) {
    if (std::string problem = layer::checkSetting(key, value); !problem.empty()) {
      err << "steadyxr: " << forCommandLine(problem) << "\n";
      err << "steadyxr: " << path << " not changed\n";
      return 1;
    }
    if (value.find_first_of("\n\r") != std::string::npos || value.find(" #") != std::string::npos) {
      err << "steadyxr: the value of " << key << " cannot hold a line break or ' #' (a comment)\n";
      return 1;
    }
  }
  Edit edit;
  if (!readForEdit(path, &edit, err)) return 1;
  std::string text = edit.before;
  std::string what;
  for (const auto& [key, value] : settings) {
    const std::string k = lower(trim(key));
    text = setInText(text, app, k, trim(value));
    what += (what.empty() ? "" : ", ") + k + " = " + trim(value);
  }
  return commit(edit, text, app, "set " + what + (app.empty() ? "" : " for [" + app + "]"), out, err);
}

void printSettings(const layer::Config& c, std::ostream& out) {
  const layer::Config d;
  out << "  enabled = " << (c.enabled ? 1 : 0) << "\n";
  out << "  method = " << c.method << "\n";
  if (c.profile != "default") {
    out << "  profile = " << c.profile << " (sets";
    const char* sep = " ";
    for (const layer::ProfileSetting& p :
         layer::profileSettings(c.profile).value_or(std::span<const layer::ProfileSetting>{})) {
      out << sep << p.key << " = " << p.value;
      sep = ", ";
    }
    out << ")\n";
  }
  out << "  pose_source = " << (c.poseSource == layer::PoseSourceKind::Imu ? "imu" : "runtime") << "\n";
  if (c.poseSource == layer::PoseSourceKind::Imu) out << "  imu_device = " << c.imuDevice << "\n";
  out << "  log_level = " << layer::toString(c.logLevel) << "\n";
  if (!c.logFile.empty()) out << "  log_file = " << c.logFile << "\n";
  if (c.dumpFrames > 0) out << "  dump_frames = " << c.dumpFrames << " (to " << c.dumpDir << ")\n";
  if (c.jitter) out << "  jitter = 1\n";
}

int show(const std::string& app, const std::string& path, const layer::EnvLookup& env, std::ostream& out,
         std::ostream& err) {
  Edit edit;
  if (!readForEdit(path, &edit, err)) return 1;
  out << "config file: " << path << (edit.existed ? "" : " (does not exist: defaults)") << "\n";
  std::vector<std::string> problems;
  const layer::ConfigText parsed = layer::parseConfigText(edit.before, &problems);
  const auto noEnvironment = [](const std::string&) -> std::optional<std::string> { return std::nullopt; };
  layer::resolveConfig(parsed, "", noEnvironment, &problems);
  for (const auto& [name, keys] : parsed.sections)
    layer::resolveConfig({{}, {{name, keys}}}, name, noEnvironment, &problems);
  for (const std::string& p : problems) out << "problem: " << p << "\n";
  out << "global settings:\n";
  for (const auto& [k, v] : parsed.global) out << "  " << k << " = " << v << "\n";
  for (const auto& [name, keys] : parsed.sections) {
    out << "[" << name << "]\n";
    for (const auto& [k, v] : keys) out << "  " << k << " = " << v << "\n";
  }
  out << "in effect for " << (app.empty() ? "apps without a section" : "[" + app + "]")
      << " (file and this shell's STEADYXR_* variables):\n";
  printSettings(layer::resolveConfig(parsed, app, env, nullptr), out);
  for (const std::string& key : layer::knownConfigKeys()) {
    const std::string name = layer::envNameForKey(key);
    if (auto v = env(name))
      out << "note: " << name << "=" << *v << " is set in this shell and wins over the file\n";
  }
  return 0;
}

std::string runtimeStatusFolder(const layer::EnvLookup& env) {
  auto dir = env("XDG_RUNTIME_DIR");
  return dir && !dir->empty() ? *dir + "/" + layer::kStatusFolderName : std::string();
}

// True when the status file was written by a process that still runs.
bool alive(const std::map<std::string, std::string>& status) {
  const auto pid = status.find("pid");
  if (pid == status.end()) return false;
  long id = 0;
  try {
    id = std::stol(pid->second);
  } catch (const std::exception&) {
    return false;
  }
  const auto recorded = status.find("process_start_ticks");
  if (recorded != status.end()) {
    if (const std::optional<uint64_t> ticks = layer::processStartTicks(id)) {
      return recorded->second == std::to_string(*ticks);  // else: the pid was reused
    }
  }
  // Without /proc (a chroot) or a recorded start time: whether the pid exists at all.
  return id > 0 && (::kill(static_cast<pid_t>(id), 0) == 0 || errno == EPERM);
}

std::string field(const std::map<std::string, std::string>& s, const std::string& key,
                  const std::string& fallback = "?") {
  auto it = s.find(key);
  return it == s.end() ? fallback : it->second;
}

int status(const layer::EnvLookup& env, std::ostream& out, std::ostream& err) {
  const std::string folder = runtimeStatusFolder(env);
  if (folder.empty()) {
    err << "steadyxr: XDG_RUNTIME_DIR is not set: the layer publishes no status without it\n";
    return 1;
  }
  std::vector<fs::path> files;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.size() > 7 && name.ends_with(layer::kStatusSuffix)) files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  int shown = 0;
  int removed = 0;
  for (const fs::path& file : files) {
    std::string error;
    const std::optional<std::string> text = layer::readConfigFile(file.string(), &error);  // same limits
    if (!text) continue;
    const std::map<std::string, std::string> s = layer::parseStatus(*text);
    if (!alive(s)) {
      // Left by a process that ended without removing it (killed, crashed): clean it up.
      if (fs::remove(file, ec)) ++removed;
      continue;
    }
    ++shown;
    out << field(s, "app") << " (pid " << field(s, "pid") << "): " << field(s, "state") << ", method "
        << field(s, "method") << (s.count("passes") ? " (" + field(s, "passes") + ")" : "") << ", enabled "
        << field(s, "enabled") << ", pose " << field(s, "pose_source") << "\n";
    out << "  frames: " << field(s, "frames_filtered", "0") << " filtered, "
        << field(s, "frames_passed_through", "0") << " passed through";
    std::string reasons;
    for (const auto& [k, v] : s) {
      if (k.starts_with("passed_")) reasons += (reasons.empty() ? "" : ", ") + k.substr(7) + "=" + v;
    }
    if (!reasons.empty()) out << " (" << reasons << ")";
    out << ", " << field(s, "frames_warming_up", "0") << " warming up";
    // Compiles after filtering began (a method switched live) are the user's own doing: said apart.
    if (const std::string late = field(s, "frames_warming_up_late", "0"); late != "0")
      out << " (" << late << " after filtering began)";
    out << ", " << field(s, "frames_disabled", "0") << " disabled\n";
    if (s.count("gpu_ms_total")) {
      out << "  gpu ms per frame (mean): temporal " << field(s, "gpu_ms_temporal") << ", stereo "
          << field(s, "gpu_ms_stereo") << ", other " << field(s, "gpu_ms_other") << ", total "
          << field(s, "gpu_ms_total") << "\n";
    }
    out << "  config: " << field(s, "config") << " (watching " << field(s, "config_watched", "nothing")
        << ", edits applied: " << field(s, "config_generation", "0") << ")\n";
  }
  if (shown == 0) out << "no running steadyxr instances (" << folder << ")\n";
  if (removed > 0) out << "removed " << removed << " stale status file" << (removed == 1 ? "" : "s") << "\n";
  return 0;
}

}  // namespace

std::string setInText(std::string_view text, const std::string& section, const std::string& key,
                      const std::string& value) {
  std::vector<std::string> lines = splitLines(text);
  const Part part = findPart(lines, section, key);
  if (!part.keyLines.empty()) {
    const size_t last = part.keyLines.back();
    lines[last] = settingLine(key, value, lines[last]);
    // Earlier settings of the key in the same part would only draw a duplicate warning.
    for (auto it = part.keyLines.rbegin() + 1; it != part.keyLines.rend(); ++it) {
      lines.erase(lines.begin() + static_cast<std::ptrdiff_t>(*it));
    }
    return joinLines(lines);
  }
  const std::string line = key + " = " + value;
  if (part.lastSetting) {
    lines.insert(lines.begin() + static_cast<std::ptrdiff_t>(*part.lastSetting + 1), line);
  } else if (part.header) {
    lines.insert(lines.begin() + static_cast<std::ptrdiff_t>(*part.header + 1), line);
  } else if (section.empty()) {
    // No global setting yet: before the first section (after the comments that open the file).
    const size_t at = part.firstSectionHeader.value_or(lines.size());
    lines.insert(lines.begin() + static_cast<std::ptrdiff_t>(at), line);
    if (part.firstSectionHeader) lines.insert(lines.begin() + static_cast<std::ptrdiff_t>(at + 1), "");
  } else {
    if (!lines.empty() && !trim(lines.back()).empty()) lines.emplace_back();
    lines.push_back("[" + section + "]");
    lines.push_back(line);
  }
  return joinLines(lines);
}

std::string unsetInText(std::string_view text, const std::string& section, const std::string& key) {
  std::vector<std::string> lines = splitLines(text);
  const Part part = findPart(lines, section, key);
  for (auto it = part.keyLines.rbegin(); it != part.keyLines.rend(); ++it) {
    lines.erase(lines.begin() + static_cast<std::ptrdiff_t>(*it));
  }
  return part.keyLines.empty() ? std::string(text) : joinLines(lines);
}

bool writeFileAtomically(const std::string& path, const std::string& content, std::string* error) {
  std::error_code ec;
  fs::path target = path;
  if (fs::is_symlink(target, ec)) target = fs::weakly_canonical(target, ec);  // write where it points
  const fs::path folder = target.parent_path().empty() ? fs::path(".") : target.parent_path();
  fs::create_directories(folder, ec);
  if (ec) {
    *error = "cannot create " + folder.string() + ": " + ec.message();
    return false;
  }
  struct stat st {};
  const mode_t mode = ::stat(target.c_str(), &st) == 0 ? (st.st_mode & 07777) : 0644;
  const std::string tmp = target.string() + ".tmp-" + std::to_string(::getpid());
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, mode);
  if (fd < 0) {
    *error = "cannot create " + tmp + ": " + std::generic_category().message(errno);
    return false;
  }
  const bool written = layer::writeAll(fd, content);
  const int saved = errno;
  const bool ok = written && ::fsync(fd) == 0;
  ::close(fd);
  if (!ok || ::rename(tmp.c_str(), target.c_str()) != 0) {
    *error = "cannot write " + target.string() + ": " + std::generic_category().message(ok ? errno : saved);
    ::unlink(tmp.c_str());
    return false;
  }
  return true;
}

int run(const std::vector<std::string>& argsIn, const layer::EnvLookup& env, std::ostream& out,
        std::ostream& err) {
  std::vector<std::string> args = argsIn;
  std::optional<std::string> configOption;
  if (args.size() >= 2 && args[0] == "--config") {
    configOption = args[1];
    args.erase(args.begin(), args.begin() + 2);
  }
  if (args.empty()) {
    err << kUsage;
    return 2;
  }
  const std::string verb = args[0];
  if (verb == "help" || verb == "--help" || verb == "-h") {
    out << kUsage;
    return 0;
  }
  std::string app;
  std::vector<std::string> rest;
  for (size_t i = 1; i < args.size(); ++i) {
    if (args[i] == "--app") {
      if (i + 1 >= args.size()) {
        err << "steadyxr: --app needs the app's name\n";
        return 2;
      }
      app = args[++i];
      if (!validAppName(app, err)) return 2;
    } else if (args[i].starts_with("--app=")) {
      app = args[i].substr(6);
      if (!validAppName(app, err)) return 2;
    } else if (args[i] == "--help" || args[i] == "-h") {
      out << kUsage;
      return 0;
    } else {
      rest.push_back(args[i]);
    }
  }
  const std::string path = configPath(configOption, env);
  if (path.empty() && verb != "status") {
    err << "steadyxr: no config file: set XDG_CONFIG_HOME or HOME, or pass --config FILE\n";
    return 1;
  }
  if (verb == "enable" || verb == "disable") {
    if (!rest.empty()) {
      err << "steadyxr: " << verb << " takes no arguments but --app NAME\n";
      return 2;
    }
    return setKeys({{"enabled", verb == "enable" ? "1" : "0"}}, app, path, out, err);
  }
  if (verb == "set") {
    if (rest.empty()) {
      err << "steadyxr: set needs KEY=VALUE, e.g. `steadyxr set method=taa`\n";
      return 2;
    }
    std::vector<std::pair<std::string, std::string>> settings;
    for (const std::string& a : rest) {
      const size_t eq = a.find('=');
      if (eq == std::string::npos || trim(a.substr(0, eq)).empty()) {
        err << "steadyxr: '" << a << "' is not KEY=VALUE\n";
        return 2;
      }
      settings.emplace_back(trim(a.substr(0, eq)), trim(a.substr(eq + 1)));
    }
    return setKeys(settings, app, path, out, err);
  }
  if (verb == "unset") {
    if (rest.empty()) {
      err << "steadyxr: unset needs a KEY\n";
      return 2;
    }
    Edit edit;
    if (!readForEdit(path, &edit, err)) return 1;
    std::string text = edit.before;
    for (const std::string& key : rest) {
      const std::vector<std::string> keys = layer::knownConfigKeys();
      if (std::find(keys.begin(), keys.end(), lower(key)) == keys.end()) {
        err << "steadyxr: unknown key '" << key << "'; " << path << " not changed\n";
        return 1;
      }
      text = unsetInText(text, app, lower(key));
    }
    if (!edit.existed) {
      out << "nothing to unset (" << path << " does not exist)\n";
      return 0;
    }
    return commit(edit, text, app, "unset " + lower(rest[0]) + (rest.size() > 1 ? " and more" : ""), out,
                  err);
  }
  if (verb == "show") {
    if (!rest.empty()) {
      err << "steadyxr: show takes no arguments but --app NAME\n";
      return 2;
    }
    return show(app, path, env, out, err);
  }
  if (verb == "status") return status(env, out, err);
  err << "steadyxr: unknown command '" << verb << "'\n" << kUsage;
  return 2;
}

}  // namespace steadyxr::cli
