// The command line of the varia program (spec: "Commands", "Exit codes").
#pragma once

#include <functional>
#include <string>

namespace varia::host {

// Parses the command line, runs the subcommand, and maps errors to exit codes: every non-zero
// exit prints exactly one line "varia: error: ..." to stderr. It sets up the process first: closed
// standard descriptors opened, interrupt and crash handlers installed.
int main_cli(int argc, char** argv);

// The command line alone, without the process's setup: parses it and runs the command, as
// main_cli does, when `runs` allows the command's name (else 0 once it is parsed). For the
// fuzzer (tests/fuzz), which parses every command line and runs only the quick commands.
int run_command_line(int argc, char** argv, const std::function<bool(const std::string& command)>& runs);

}  // namespace varia::host
