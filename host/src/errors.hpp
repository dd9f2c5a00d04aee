// The host's error classes and the exit codes they map to (spec: "Exit codes").
#pragma once

#include <exception>
#include <stdexcept>
#include <string>

namespace varia::host {

// Bad input (exit code 2): the message names what was wrong and what was expected; for a scene
// field, it starts with the field's JSON pointer.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// An output that cannot be written or closed (a full disk, a missing directory, a file another
// run is writing): exit code 2 like an unwritable --out, the message naming the file
// (docs/security.md, "Outputs").
class OutputError : public InputError {
 public:
  using InputError::InputError;
};

// A plugin that cannot be loaded or misbehaves (exit code 3): the message names the file.
// (varia::PluginFault from core is the same exit code.)
class PluginLoadError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Exit codes (spec: "Exit codes").
inline constexpr int kExitOk = 0;
inline constexpr int kExitInput = 2;
inline constexpr int kExitPlugin = 3;
inline constexpr int kExitNumerical = 4;

// The exit code of a command that ended with `failure` (an InputError 2, a plugin fault 3, a
// numerical failure 4, ...), and its message: `varia`'s own (cli.cpp) and each ensemble member's
// status, which is the exit code its own `varia run` would have had. Rethrows an exception that is
// not a std::exception.
int exit_code_of(std::exception_ptr failure, std::string& message);

}  // namespace varia::host
