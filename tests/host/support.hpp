// Helpers of the host tests: temporary directories, running the varia program, reading files.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <doctest/doctest.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace varia::test {

namespace fs = std::filesystem;

inline const fs::path kBuildDir = VARIA_BUILD_DIR;
inline const fs::path kSourceDir = VARIA_SOURCE_DIR;
inline const fs::path kPluginDir = kBuildDir / "lib" / "varia" / "plugins";

// The program under test: build/bin/varia, or VARIA_TEST_PROGRAM (to run the tests against another
// build, e.g. one from before a fix, to see them fail).
inline fs::path varia_program() {
  const char* other = std::getenv("VARIA_TEST_PROGRAM");
  return other != nullptr && *other != '\0' ? fs::path(other) : kBuildDir / "bin" / "varia";
}

// A directory of its own for one test, removed with everything in it at the end.
class TempDir {
 public:
  TempDir() {
    static std::atomic<int> counter{0};
    path_ = fs::temp_directory_path() /
            ("varia-host-test-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
    fs::create_directories(path_);
    // Only the owner may write it, whatever the umask: the registry refuses plugin directories
    // that group or others can write.
    fs::permissions(path_, fs::perms::owner_all);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const fs::path& path() const { return path_; }
  fs::path operator/(const std::string& name) const { return path_ / name; }

 private:
  fs::path path_;
};

inline std::string read_file(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

inline void write_file(const fs::path& file, const std::string& text) {
  std::ofstream(file, std::ios::binary) << text;
}

inline std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

struct Outcome {
  int code = -1;
  std::string out, err;
};

// Runs build/bin/varia with `arguments` (already shell-quoted where needed) from the source
// directory, so that scene paths like scenes/default.json work.
inline Outcome run_varia(const std::string& arguments) {
  TempDir dir;
  const auto out = dir / "stdout", err = dir / "stderr";
  const std::string command = "cd '" + kSourceDir.string() + "' && '" + varia_program().string() +
                              "' " + arguments + " > '" + out.string() + "' 2> '" + err.string() + "'";
  const int status = std::system(command.c_str());
  Outcome outcome;
  outcome.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  outcome.out = read_file(out);
  outcome.err = read_file(err);
  return outcome;
}

// Runs `shell` (a /bin/sh command line, run from the source directory) with stdout and stderr
// captured, unless the command redirects them itself.
inline Outcome run_shell(const std::string& shell) {
  TempDir dir;
  const std::string command = "cd '" + kSourceDir.string() + "' && { " + shell + " ; } > '" +
                              (dir / "stdout").string() + "' 2> '" + (dir / "stderr").string() + "'";
  const int status = std::system(command.c_str());
  return Outcome{WIFEXITED(status) ? WEXITSTATUS(status) : -1, read_file(dir / "stdout"), read_file(dir / "stderr")};
}

// The program under test and a file name, quoted for run_shell.
inline std::string varia() { return "'" + varia_program().string() + "'"; }
inline std::string quoted(const fs::path& file) { return "'" + file.string() + "'"; }

inline bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// Spec "Exit codes": a non-zero exit prints one line to stderr, "varia: error: ...", naming the cause.
inline void check_one_error_line(const Outcome& outcome, const std::string& expected) {
  const auto lines = lines_of(outcome.err);
  REQUIRE(lines.size() == 1);
  CHECK(lines[0].rfind("varia: error: ", 0) == 0);
  CHECK(contains(lines[0], expected));
}

// The files of a directory with this extension, sorted.
inline std::vector<fs::path> files_in(const fs::path& directory, const std::string& extension) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(directory))
    if (entry.path().extension() == extension) files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace varia::test
