#include "interrupt.hpp"

#include <fmt/format.h>

#include <csignal>

namespace varia::host {

namespace {

volatile std::sig_atomic_t requested = 0;

struct StopSignal {
  int number;
  const char* name;
};

const StopSignal kStopSignals[] = {{SIGHUP, "SIGHUP"},   {SIGINT, "SIGINT"},   {SIGTERM, "SIGTERM"},
                                   {SIGALRM, "SIGALRM"}, {SIGUSR1, "SIGUSR1"}, {SIGUSR2, "SIGUSR2"},
                                   {SIGXCPU, "SIGXCPU"}};

void on_signal(int signal) {
  if (requested != 0) {  // the second one: the default action, now
    std::signal(signal, SIG_DFL);
    std::raise(signal);
    return;
  }
  requested = signal;
}

}  // namespace

void install_interrupt_handlers() {
  struct sigaction action {};
  action.sa_handler = on_signal;
  action.sa_flags = SA_RESTART;  // a write in progress is finished, not cut
  sigemptyset(&action.sa_mask);
  for (const StopSignal& s : kStopSignals) sigaddset(&action.sa_mask, s.number);  // one handler at a time
  for (const StopSignal& s : kStopSignals) {
    struct sigaction before {};
    // A signal ignored when varia starts stays ignored (nohup's SIGHUP, a background job's SIGINT).
    if (sigaction(s.number, nullptr, &before) == 0 && before.sa_handler == SIG_IGN) continue;
    sigaction(s.number, &action, nullptr);
  }
}

int interruption() { return requested; }

std::string signal_name(int signal) {
  for (const StopSignal& s : kStopSignals)
    if (s.number == signal) return s.name;
  return fmt::format("signal {}", signal);
}

Interrupted::Interrupted(int signal, const std::string& where)
    : std::runtime_error(fmt::format("interrupted by {} {}", signal_name(signal), where)), signal_(signal) {}

void stop_if_interrupted(const std::string& where) {
  if (const int signal = interruption(); signal != 0) throw Interrupted(signal, where);
}

}  // namespace varia::host
