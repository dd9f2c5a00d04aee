// SIGINT and SIGTERM (docs/security.md, "Interrupts"): the first one asks the running command to
// stop at its next step boundary, so that the trajectory ends with a whole row and the run record
// notes the interruption; the command then ends with exit code 128 + the signal's number (130,
// 143). A second signal ends the program at once, as the signal's default action does.
#pragma once

#include <stdexcept>
#include <string>

namespace varia::host {

void install_interrupt_handlers();

// The signal that asked to stop (SIGINT or SIGTERM), or 0.
int interruption();

// "SIGINT" or "SIGTERM".
std::string signal_name(int signal);

// Thrown where a command stops for an interruption; cli.cpp maps it to 128 + signal.
class Interrupted : public std::runtime_error {
 public:
  explicit Interrupted(int signal, const std::string& where);
  int signal() const { return signal_; }

 private:
  int signal_;
};

// Throws Interrupted when a signal asked to stop.
void stop_if_interrupted(const std::string& where);

}  // namespace varia::host
