// The command line of the varia program (spec: "Commands", "Exit codes").
#pragma once

namespace varia::host {

// Parses the command line, runs the subcommand, and maps errors to exit codes: every non-zero
// exit prints exactly one line "varia: error: ..." to stderr.
int main_cli(int argc, char** argv);

}  // namespace varia::host
