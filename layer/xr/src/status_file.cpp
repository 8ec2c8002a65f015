#include "status_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <system_error>

namespace steadyxr::layer {
namespace {

std::string errnoText() {
  return std::generic_category().message(errno);
}

}  // namespace

std::unique_ptr<StatusFile> StatusFile::create(const std::string& runtimeDir, std::string* error) {
  const auto fail = [&](const std::string& why) -> std::unique_ptr<StatusFile> {
    if (error) *error = why;
    return nullptr;
  };
  if (runtimeDir.empty()) return fail("XDG_RUNTIME_DIR is not set");
  const std::string folder = runtimeDir + "/" + kStatusFolderName;
  if (::mkdir(folder.c_str(), 0700) != 0 && errno != EEXIST)
    return fail("cannot create " + folder + ": " + errnoText());
  struct stat st {};
  if (::lstat(folder.c_str(), &st) != 0 || !S_ISDIR(st.st_mode) || st.st_uid != ::geteuid()) {
    return fail(folder + " is not a folder of this user");
  }
  static std::atomic<unsigned> serial{0};
  return std::unique_ptr<StatusFile>(new StatusFile(folder + "/" + std::to_string(::getpid()) + "-" +
                                                    std::to_string(++serial) + kStatusSuffix));
}

StatusFile::~StatusFile() {
  ::unlink(path_.c_str());
}

bool writeAll(int fd, std::string_view data) {
  size_t done = 0;
  while (done < data.size()) {
    const ssize_t n = ::write(fd, data.data() + done, data.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += static_cast<size_t>(n);
  }
  return true;
}

bool StatusFile::write(const std::string& content, std::string* error) {
  const std::string tmp = path_ + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC | O_NOFOLLOW, 0600);
  if (fd < 0) {
    if (error) *error = "cannot write " + tmp + ": " + errnoText();
    return false;
  }
  const bool written = writeAll(fd, content);
  ::close(fd);
  if (!written || ::rename(tmp.c_str(), path_.c_str()) != 0) {
    if (error) *error = "cannot write " + path_ + ": " + errnoText();
    ::unlink(tmp.c_str());
    return false;
  }
  return true;
}

std::optional<uint64_t> processStartTicks(long pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // Field 2 (comm) is in parentheses and may hold spaces: count fields after its last ')'.
  const size_t close = text.rfind(')');
  if (!in.good() && text.empty()) return std::nullopt;
  if (close == std::string::npos) return std::nullopt;
  std::istringstream fields(text.substr(close + 1));
  std::string field;
  for (int i = 3; i <= 22; ++i) {  // fields 3..22
    if (!(fields >> field)) return std::nullopt;
  }
  try {
    return std::stoull(field);
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

std::map<std::string, std::string> parseStatus(const std::string& text) {
  std::map<std::string, std::string> out;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    const size_t eq = line.find('=');
    if (eq == std::string::npos || eq == 0) continue;
    out[line.substr(0, eq)] = line.substr(eq + 1);
  }
  return out;
}

}  // namespace steadyxr::layer
