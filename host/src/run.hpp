// `varia run`: the stepping loop, the trajectory CSV and the run record (spec: "Outputs").
#pragma once

#include <filesystem>
#include <optional>
#include <vector>

#include "assemble.hpp"
#include "scene.hpp"

namespace varia::host {

class Registry;

struct RunOptions {
  std::optional<std::filesystem::path> out;      // trajectory CSV ("-": stdout); none: not written
  std::optional<std::filesystem::path> summary;  // run record JSON
  std::optional<std::filesystem::path> plot;     // SVG of q(t) and the energy error (or p(t))
  bool quiet = false;                             // no progress line, no human summary
};

// What the run record reports besides the trajectory's state: the seconds of the stepping loop
// with its observing and writing (the record's wall_seconds; the benchmarks read it).
struct RunOutcome {
  double wall_seconds = 0.0;
};

// Steps the scene's integrator to its last step. On a NumericalFailure the rows written so far
// stay whole, the run record is written with a "failure" key, and a NumericalFailure naming the
// step index, time and residual is thrown.
RunOutcome run_scene(const Scene& scene, Assembly& assembly, const Registry& registry, const RunOptions& options);

}  // namespace varia::host
