// `varia run`: the stepping loop, the trajectory CSV and the run record (spec: "Outputs").
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "assemble.hpp"
#include "scene.hpp"

namespace varia::host {

class Registry;

// A trajectory kept in memory (the Python module's Run): its observable columns once, then every
// row the outputs would get (output.every).
class TrajectoryRecorder {
 public:
  virtual ~TrajectoryRecorder() = default;
  virtual void columns(int point_size, int dim, const std::vector<std::string>& observables) = 0;
  virtual void row(double t, const double* q, const double* p, const std::vector<double>& observables) = 0;
};

struct RunOptions {
  std::optional<std::filesystem::path> out;      // trajectory CSV ("-": stdout); none: not written
  std::optional<std::filesystem::path> summary;  // run record JSON
  std::optional<std::filesystem::path> plot;     // SVG of q(t) and the energy error (or p(t))
  bool quiet = false;                             // no progress line, no human summary
  bool warnings = true;                           // departure warnings on stderr (always in the record)
  TrajectoryRecorder* rows = nullptr;             // also receives the rows, when given
  nlohmann::json* record = nullptr;               // receives the run record, when given
};

// A run's failed step (exit 4): the step, the time it started from and, as every NumericalFailure,
// the residual and the message.
class RunFailure : public NumericalFailure {
 public:
  RunFailure(const std::string& what, double residual, const void* origin, long step, double t)
      : NumericalFailure(what, residual, origin), step_(step), t_(t) {}
  long step() const { return step_; }
  double t() const { return t_; }

 private:
  long step_;
  double t_;
};

// What the run record reports besides the trajectory's state: the seconds of the stepping loop
// with its observing and writing (the record's wall_seconds; the benchmarks read it).
struct RunOutcome {
  double wall_seconds = 0.0;
};

// Steps the scene's integrator to its last step. On a NumericalFailure the rows written so far
// stay whole, the run record is written with a "failure" key, and a RunFailure naming the step
// index, time and residual is thrown.
RunOutcome run_scene(const Scene& scene, Assembly& assembly, const Registry& registry, const RunOptions& options);

}  // namespace varia::host
