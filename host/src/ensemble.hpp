// `varia ensemble` (spec "Tangent maps and ensembles", docs/ensembles.md): one member per element
// of the product of the --vary specs, each the scene with its values set at their JSON pointers and
// run as `varia run` would run it, on threads, or across the processes of `mpirun` (Open MPI: rank
// 0 runs members on a thread of its own, hands out the others as processes finish, and writes the one
// HDF5 file, ensemble_file.hpp).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "commands.hpp"

namespace varia::host {

// One --vary: a JSON pointer and its values.
struct VarySpec {
  std::string text;  // as given, POINTER=SPEC
  std::string pointer;
  std::vector<double> values;
};

// POINTER=linspace:A:B:N (N >= 1 values from A to B), list:A,B,... or uniform:A:B:N:SEED (N values
// uniform in [A, B) from the 64-bit Mersenne twister seeded with SEED, the top 53 bits of each draw:
// the same on every machine). InputError naming --vary otherwise.
VarySpec parse_vary(const std::string& text);

struct EnsembleOptions {
  std::vector<std::string> vary;
  std::filesystem::path out;
  std::optional<std::filesystem::path> plot;  // the stability map: megno_final over the two --vary
  int threads = 1;
  bool resume = false, quiet = false;
};

int command_ensemble(const CommonOptions& common, const std::string& scene_file, const EnsembleOptions& options);

}  // namespace varia::host
