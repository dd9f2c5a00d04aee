// The signals that ask varia to stop (docs/security.md, "Interrupts"): SIGHUP, SIGINT, SIGTERM,
// SIGALRM, SIGUSR1, SIGUSR2 and SIGXCPU. The first one asks the running command to stop at its
// next boundary (a step in `run`, a step size in `cost` and `verify`), so that the trajectory ends
// with a whole row and the run record notes the interruption; the command then ends with exit code
// 128 + the signal's number (129, 130, 143, ...). A second signal ends the program at once, as the
// signal's default action does. SIGQUIT keeps its default action (at once, with a core dump where
// enabled), SIGPIPE too; a signal ignored when varia starts (nohup's SIGHUP) stays ignored.
#pragma once

#include <stdexcept>
#include <string>

namespace varia::host {

void install_interrupt_handlers();

// The signal that asked to stop, or 0.
int interruption();

// Its name: "SIGINT", "SIGTERM", "SIGHUP", ...
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
