// The members of `varia ensemble` (ensemble.hpp) and their dispatch, which the threads of a process
// (ensemble.cpp) and the processes of mpirun (ensemble_mpi.cpp) share.
#pragma once

#include <exception>
#include <mutex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "ensemble.hpp"
#include "ensemble_file.hpp"
#include "interrupt.hpp"
#include "progress.hpp"
#include "registry.hpp"

namespace varia::host {

// The ensemble: the scene (with --set applied), the specs, and what its file holds.
struct Plan {
  nlohmann::json document;
  std::string scene_text, vary_text;
  std::vector<VarySpec> varies;
  EnsembleLayout layout;
  std::vector<double> parameters;  // members x varies, row-major: the product, the first --vary slowest
};

// One member, run as `varia run` runs its scene, with nothing written: its status, final state and
// record numbers. Scenes are prepared one at a time (`prepare`: the scene's validators are shared);
// the runs themselves in parallel. Interrupted propagates (the member is not recorded).
MemberResult run_member(const Plan& plan, long member, Registry& registry, std::mutex& prepare, std::string& message);

// A failed member's line on stderr (by the process that ran it).
void say_failure(const Plan& plan, long member, const MemberResult& r, const std::string& message);

// The members still to run, handed out one at a time (take), and the file their results go to
// (record), shared by this process's threads and, under mpirun, rank 0's service of the others.
class Dispatcher {
 public:
  Dispatcher(const Plan& plan, const std::vector<long>& todo, EnsembleFile& file, ProgressLine& progress)
      : plan_(plan), todo_(todo), file_(file), progress_(progress) {}
  // The next member, or -1: none left, or an interruption or a failed write stopped the ensemble.
  long take() {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (interruption() != 0 || failure_ || next_ >= todo_.size()) return -1;
    return todo_[next_++];
  }
  void record(long member, const MemberResult& r, const std::string& message) {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (failure_) return;
    try {
      file_.write(member, r);
    } catch (...) {
      failure_ = std::current_exception();
      return;
    }
    say_failure(plan_, member, r, message);
    progress_.update(++done_);
  }
  // Takes and runs members until none is left, with a registry of its own.
  void work(const CommonOptions& common) {
    Registry registry = make_registry(common);
    for (long member; (member = take()) >= 0;) {
      std::string message;
      try {
        const MemberResult r = run_member(plan_, member, registry, prepare_, message);
        record(member, r, message);
      } catch (const Interrupted&) {
        return;
      }
    }
  }
  // A failed write ends the command, once the threads are done.
  void rethrow() const {
    if (failure_) std::rethrow_exception(failure_);
  }
  const Plan& plan() const { return plan_; }
  long done() const { return done_; }

 private:
  const Plan& plan_;
  const std::vector<long>& todo_;
  EnsembleFile& file_;
  ProgressLine& progress_;
  std::mutex mutex_, prepare_;
  std::size_t next_ = 0;
  long done_ = 0;  // members recorded by this command
  std::exception_ptr failure_;
};

}  // namespace varia::host
