// Status of a running layer instance: a small key=value file under
// $XDG_RUNTIME_DIR/steadyxr/ (the user's own 0700 folder; no sockets), rewritten about once a
// second through a temporary file and rename(2) so a reader never sees half a file, and
// removed when the instance ends. `steadyxr status` reads them.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace steadyxr::layer {

inline constexpr char kStatusFolderName[] = "steadyxr";
inline constexpr char kStatusSuffix[] = ".status";

class StatusFile {
 public:
  // The file <runtimeDir>/steadyxr/<pid>-<serial>.status (serial: the instance's number in this
  // process). nullptr and *error when the folder cannot be made private or is not ours.
  static std::unique_ptr<StatusFile> create(const std::string& runtimeDir, std::string* error);
  ~StatusFile();  // removes the file
  StatusFile(const StatusFile&) = delete;
  StatusFile& operator=(const StatusFile&) = delete;

  // Replaces the file's content atomically. False (and *error) on failure.
  bool write(const std::string& content, std::string* error);
  const std::string& path() const { return path_; }

 private:
  explicit StatusFile(std::string path) : path_(std::move(path)) {}
  std::string path_;
};

// The start time of process `pid` in clock ticks since boot (/proc/<pid>/stat, field 22): with
// the pid it names a process uniquely, so a status file left by a dead process is recognised
// even when its pid was reused. nullopt when the process does not exist.
std::optional<uint64_t> processStartTicks(long pid);

// Writes all of `data` to `fd`, retrying short writes and EINTR; false on any other failure.
// (The status file and the `steadyxr` tool's atomic config write both need it.)
bool writeAll(int fd, std::string_view data);

// "key=value" lines into a map (later keys win; other lines are skipped).
std::map<std::string, std::string> parseStatus(const std::string& text);

}  // namespace steadyxr::layer
