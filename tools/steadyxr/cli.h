// The `steadyxr` command: edits the per-user config file with the layer's own parser (what it
// accepts, the layer accepts) and lists the running layer instances from their status files.
// A library apart from main() so that the unit tests drive every verb.
#pragma once

#include "config.h"

#include <ostream>
#include <string>
#include <string_view>
#include <vector>

namespace steadyxr::cli {

// Runs one command line (without the program name). Returns the exit status: 0 done, 1 an error
// (the config file is left as it was), 2 a usage error.
int run(const std::vector<std::string>& args, const layer::EnvLookup& env, std::ostream& out,
        std::ostream& err);

// The text with `key = value` set in [section] (empty: the global part before any section):
// the last line that sets the key is replaced (its trailing comment kept), earlier ones in the
// same part are removed, and a new key goes after the part's last setting. Comments, blank lines
// and everything else stay as they were.
std::string setInText(std::string_view text, const std::string& section, const std::string& key,
                      const std::string& value);
// The text without any line that sets `key` in [section].
std::string unsetInText(std::string_view text, const std::string& section, const std::string& key);

// Replaces `path` atomically (a temporary file in the same folder, fsync, rename): a reader -
// the layer reloading on inotify - sees the old file or the new one, never half of one. A
// symlink is followed, so a dotfile manager's link stays a link. False and *error on failure.
bool writeFileAtomically(const std::string& path, const std::string& content, std::string* error);

}  // namespace steadyxr::cli
