// Whether a plugin file may be loaded (docs/security.md, "How plugins are trusted"): whoever can
// write the file, or a directory above it, could make the host run their code.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace varia::host {

// The entries of a colon-separated list in the environment variable `variable`, in order (empty
// entries skipped).
std::vector<std::filesystem::path> path_list(const char* variable);

// The directories the user trusts with what its group may write (VARIA_TRUSTED_PLUGIN_DIRS), each
// canonical. Throws InputError for an entry that is not an absolute path of a directory.
std::vector<std::filesystem::path> trusted_directories();

// Why a plugin file may not be trusted, or "" when it may (as sshd's StrictModes and sudo check).
// The file is followed through symbolic links to the file itself, and the directories of the path
// as given are checked too: a link in a directory another user can write could be pointed
// elsewhere between this check and the load (which opens the canonical path).
std::string distrust(const std::filesystem::path& file, const std::vector<std::filesystem::path>& trusted);

}  // namespace varia::host
