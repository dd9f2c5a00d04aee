// `varia verify` (spec: "Commands", "Outputs"): predicts each property of the scene's integrator
// from the declared properties of its parts by the paper's theorems, measures it, and reports
// both.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "assemble.hpp"
#include "scene.hpp"

namespace varia::host {

class Registry;

struct PropertyCheck {
  std::string name;
  nlohmann::json predicted;  // true, false, an order, or null where the theorems say nothing
  std::optional<bool> holds;     // null: not measured for this construction
  std::optional<double> measured;
  double tolerance = 0.0;
  std::string note;              // how it was measured, points dropped from a fit
  // A property the theorems predict that was measured not to hold (exit code 1).
  bool failed() const;
  // A property the theorems predict that could not be measured (`note` says why): verify cannot
  // exit 0.
  bool unmeasured() const;
};

// Refuses (InputError naming --h) the step sizes given with `verify --h` unless each is accepted
// by check_step_flag over global_order's final time (kOrderSpan steps of the largest step size,
// the scene's or a given one), no two give the same number of steps to it (a repeated step size
// is one point of a fit, not two), and there are at least kMinimumFitPoints. Empty: accepted
// (verify chooses them).
void check_fit_steps(const Scene& scene, const std::vector<double>& h);

// `h`: the step sizes the orders are fitted at (varia verify --h, checked by check_fit_steps);
// empty: verify chooses them. `progress`: a progress line on stderr through the runs (where it is
// a terminal, progress.hpp).
std::vector<PropertyCheck> verify_scene(const Scene& scene, Assembly& assembly, Registry& registry,
                                        const std::vector<double>& h = {}, bool progress = false);
nlohmann::json checks_json(const std::vector<PropertyCheck>& checks);
// The table `verify` prints: property, predicted, measured, tolerance, holds, and why a property
// was not measured (at most kShortReason characters); with `explain`, each row's whole note (the
// theorem, the measurement, the fit and its dropped points) on the lines after it.
std::string checks_table(const std::vector<PropertyCheck>& checks, bool explain);

}  // namespace varia::host
