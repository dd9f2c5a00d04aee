// Output files (spec: "Outputs"): the trajectory CSV, written in whole rows so that the rows on
// disk stay whole when a run stops early, and JSON documents.
#pragma once

#include <Eigen/Core>
#include <cstdio>
#include <filesystem>
#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace varia::host {

class CsvWriter {
 public:
  // "-" writes to stdout. Throws InputError when the file cannot be opened.
  explicit CsvWriter(const std::filesystem::path& file);
  ~CsvWriter();
  CsvWriter(const CsvWriter&) = delete;
  CsvWriter& operator=(const CsvWriter&) = delete;

  void header(const std::vector<std::string>& columns);
  // One row of numbers at full precision (the shortest text that reads back to the same double);
  // it reaches the file whole.
  void row(double t, const double* a, int na, const double* b, int nb, const std::vector<double>& rest);
  void flush();

 private:
  void end_row();
  std::FILE* file_ = nullptr;
  bool owned_ = false;
  fmt::memory_buffer buffer_;
};

inline std::vector<double> as_vector(const Eigen::VectorXd& x) { return {x.data(), x.data() + x.size()}; }

// Writes a JSON document (pretty-printed) to a file, or to stdout for "-".
void write_json_file(const std::filesystem::path& file, const nlohmann::ordered_json& document);

}  // namespace varia::host
