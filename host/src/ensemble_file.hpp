// The ensemble's HDF5 file (spec "Tangent maps and ensembles", docs/ensembles.md): fixed-size
// datasets, one row per member in the product's order: `parameters` (members x varies), `status`
// (int32: the exit code the member's own `varia run` would have had; -1 where the member has not
// been run yet), `final_t`, `final_q` (members x N), `final_p` (members x M) and one dataset per
// run-record number (NaN where a member has none); the scene's text and the --vary specs as the
// root's attributes `scene` and `vary`. One process writes it (the MPI master or the threads'
// process): the members' results are a few numbers each, and serial HDF5 from Debian suffices.
//
// Written as a StagedFile (output.hpp) under a temporary name beside the target and renamed over it
// by close(), also after an interruption (the members so far; `--resume` runs the rest). With
// `resume`, the temporary file starts as a copy of the target, whose attributes must match. A
// failed write or a crash leaves the old file as it was.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "output.hpp"

namespace varia::host {

// What one member gave.
struct MemberResult {
  int status = -1;
  double t = 0.0;
  std::vector<double> q, p, numbers;  // numbers: the record's, in the layout's order
};

struct EnsembleLayout {
  long members = 0;
  int varies = 0, point_size = 0, dim = 0;
  std::vector<std::string> numbers;  // the run record's keys, one dataset each
};

class EnsembleFile {
 public:
  // Throws OutputError (the target cannot be written; with `resume`, it holds another ensemble).
  EnsembleFile(const std::filesystem::path& file, const std::string& scene_text, const std::string& vary_text,
               const EnsembleLayout& layout, const std::vector<double>& parameters, bool resume);
  ~EnsembleFile();
  EnsembleFile(const EnsembleFile&) = delete;
  EnsembleFile& operator=(const EnsembleFile&) = delete;

  // Each member's status as the file holds it (-1: not run yet).
  const std::vector<int>& statuses() const { return statuses_; }
  void write(long member, const MemberResult& result);
  // The record number `key`'s dataset (one of the layout's numbers), every member's.
  std::vector<double> numbers(const std::string& key) const;
  // Flushes, closes and renames the file over the target.
  void close();

 private:
  struct Handles;
  void create(const std::string& scene_text, const std::string& vary_text, const std::vector<double>& parameters);
  void open_copy(const std::string& scene_text, const std::string& vary_text);
  [[noreturn]] void fail(const std::string& doing, const std::string& cause);

  std::string name_;
  EnsembleLayout layout_;
  std::unique_ptr<StagedFile> staged_;
  std::unique_ptr<Handles> h_;
  std::vector<int> statuses_;
  bool closed_ = false;
};

}  // namespace varia::host
