// The progress line of long commands (spec: "Progress and diagnostics"): on stderr, only when it
// is a terminal and the command is not --quiet, "varia: step 120 of 1000 (12%), about 3 s left",
// redrawn at most every 0.2 s and erased at the end. `run` counts steps, `ensemble` members.
#pragma once

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <string>

namespace varia::host {

class ProgressLine {
 public:
  ProgressLine(const char* unit, long total, bool quiet)
      : unit_(unit), total_(total), active_(!quiet && ::isatty(STDERR_FILENO)) {}
  ~ProgressLine() {
    if (active_ && shown_) std::fputs("\r\033[K", stderr);
  }
  ProgressLine(const ProgressLine&) = delete;
  ProgressLine& operator=(const ProgressLine&) = delete;

  // `done` of the total are done; the time left is the time so far per unit times those left.
  void update(long done) {
    if (!active_ || done <= 0) return;
    const auto now = Clock::now();
    if (shown_ && now - last_ < std::chrono::milliseconds(200)) return;
    last_ = now;
    shown_ = true;
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    std::fprintf(stderr, "\rvaria: %s %ld of %ld (%.0f%%), about %.0f s left\033[K", unit_, done, total_,
                 100.0 * done / total_, elapsed / done * (total_ - done));
    std::fflush(stderr);
  }

 private:
  using Clock = std::chrono::steady_clock;
  const char* unit_;
  long total_;
  bool active_, shown_ = false;
  Clock::time_point start_ = Clock::now(), last_;
};

}  // namespace varia::host
