#include "plugin_trust.hpp"

#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <string_view>

#include "errors.hpp"
#include "output.hpp"

namespace fs = std::filesystem;

namespace varia::host {

namespace {

constexpr const char* kTrustedVariable = "VARIA_TRUSTED_PLUGIN_DIRS";

// Whether the canonical `path` is one of the `trusted` directories or lies under one.
bool is_trusted(const fs::path& path, const std::vector<fs::path>& trusted) {
  return std::any_of(trusted.begin(), trusted.end(), [&](const fs::path& directory) {
    const auto [end, at] = std::mismatch(directory.begin(), directory.end(), path.begin(), path.end());
    return end == directory.end();
  });
}

// Why a path may not be trusted, or "" when it may: it must be owned by root or by the user running
// varia, and writable by no one else (a directory writable by all is allowed only with the sticky
// bit and owned by root, as /tmp: no one else can then replace what it holds). Under a directory of
// VARIA_TRUSTED_PLUGIN_DIRS (`trusted`), it may also be owned by another user and writable by its
// group, never by others.
std::string distrust_one(const fs::path& path, bool directory, bool trusted) {
  struct stat status {};
  if (::stat(path.c_str(), &status) != 0) return fmt::format("cannot be inspected: {}", std::strerror(errno));
  if (status.st_uid != 0 && status.st_uid != ::geteuid() && !trusted)
    return fmt::format("owned by another user (uid {}); plugins are loaded only from files and directories owned "
                       "by root or by the user running varia, or under a directory of {}",
                       status.st_uid, kTrustedVariable);
  const bool shared_sticky = directory && (status.st_mode & S_ISVTX) != 0 && status.st_uid == 0;
  const mode_t writers = trusted ? S_IWOTH : S_IWGRP | S_IWOTH;
  if ((status.st_mode & writers) == 0 || shared_sticky) return "";
  return fmt::format("writable by group or others (mode {:04o}); plugins are loaded only from files and "
                     "directories that only their owner can write, or that only their group can write under a "
                     "directory of {}",
                     status.st_mode & 07777, kTrustedVariable);
}

// Why `directory` or one above it may not be trusted, or "" when none may.
std::string distrust_directories(fs::path directory, const std::vector<fs::path>& trusted) {
  for (;; directory = directory.parent_path()) {
    if (std::string why = distrust_one(directory, true, is_trusted(directory, trusted)); !why.empty())
      return fmt::format("its directory {} is {}", directory.string(), why);
    if (directory == directory.parent_path()) return "";
  }
}

}  // namespace

std::vector<fs::path> path_list(const char* variable) {
  std::vector<fs::path> paths;
  const char* value = std::getenv(variable);
  for (std::string_view rest = value != nullptr ? value : ""; !rest.empty();) {
    const auto colon = rest.find(':');
    if (const auto entry = rest.substr(0, colon); !entry.empty()) paths.emplace_back(std::string(entry));
    rest = colon == std::string_view::npos ? std::string_view() : rest.substr(colon + 1);
  }
  return paths;
}

std::vector<fs::path> trusted_directories() {
  std::vector<fs::path> trusted;
  for (const fs::path& entry : path_list(kTrustedVariable)) {
    std::error_code ec;
    const fs::path canonical = fs::canonical(entry, ec);
    if (!entry.is_absolute() || ec || !fs::is_directory(canonical, ec))
      throw InputError(fmt::format("{}: '{}': expected absolute paths of directories, separated by ':'",
                                   kTrustedVariable, printable(entry.string())));
    trusted.push_back(canonical);
  }
  return trusted;
}

std::string distrust(const fs::path& file, const std::vector<fs::path>& trusted) {
  std::error_code ec;
  const fs::path real = fs::canonical(file, ec);
  if (ec) return fmt::format("cannot be inspected: {}", ec.message());
  if (std::string why = distrust_one(real, false, is_trusted(real, trusted)); !why.empty())
    return real == file ? why : fmt::format("{} (where it links to) is {}", real.string(), why);
  if (std::string why = distrust_directories(real.parent_path(), trusted); !why.empty()) return why;
  // Lexically: each directory that holds a link on the way is checked, not only where links lead.
  const fs::path given = fs::absolute(file, ec).lexically_normal().parent_path();
  if (ec) return fmt::format("cannot be inspected: {}", ec.message());
  return distrust_directories(given, trusted);
}

}  // namespace varia::host
