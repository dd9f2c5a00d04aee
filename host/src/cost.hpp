// `varia cost` (spec: "Commands", "Outputs"): what accuracy costs in time. For each scene, the
// step size is swept over halvings; each run records the global error at the final time (against
// the exact solution where the Lagrangian has one, else against a converged reference run that
// the output names), the energy error, the seconds of the stepping loop, Newton iterations and
// plugin evaluations. Writes DIR/cost.csv, DIR/cost.svg (work-precision beside error against h
// with the predicted order's slope) and DIR/cost.json (per method: predicted order, fitted slope,
// the reference used).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "assemble.hpp"
#include "commands.hpp"
#include "observer.hpp"

namespace varia::host {

struct CostOptions {
  std::filesystem::path out = ".";
  // Step sizes to run; empty: the default sweep, the scene's step times 4, 2, 1, 1/2, ..., 1/16.
  // Each h is adjusted to t_end / round(t_end / h) so that every run ends at the scene's time.
  std::vector<double> h;
  bool quiet = false;  // no progress line and no table on stdout
};

// The final state of a run and the seconds of its stepping alone (what cost.csv and the benchmarks
// report): `steps` steps of size h from the assembly's initial state. The observer, if given,
// sees the initial state and then every max(1, steps / 1000)-th state between timed stretches,
// so observing costs no measured time. Throws NumericalFailure on a non-finite state.
struct TimedRun {
  Eigen::VectorXd q, p;
  double seconds = 0.0;
};
TimedRun run_timed(const Assembly& assembly, double h, long steps, Observer* observer = nullptr);

int command_cost(const CommonOptions& common, const std::vector<std::string>& scene_files,
                 const CostOptions& options);

}  // namespace varia::host
