// The trajectory as HDF5 (spec "Outputs", `--out FILE.h5`), through the HDF5 C library from
// Debian: datasets `t` (rows), `q` (rows x N), `p` (rows x M) and one per observable (`energy`;
// `momentum` rows x k; `orthogonality`), rows as the CSV's, and the scene's JSON text as the
// root's attribute `scene`. The datasets are chunked and grow: rows are buffered and appended in
// blocks, and the file is flushed after each block, so that when a run ends early (exit 4, an
// interruption) the rows written so far are readable. Every HDF5 call is checked: a failure
// throws OutputError naming the file.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace varia::host {

class Hdf5Writer {
 public:
  // Creates (truncates) the file and writes the `scene` attribute. Throws OutputError.
  Hdf5Writer(const std::filesystem::path& file, const std::string& scene_text);
  ~Hdf5Writer();  // closes what is open, reporting nothing: call close() to have errors reported
  Hdf5Writer(const Hdf5Writer&) = delete;
  Hdf5Writer& operator=(const Hdf5Writer&) = delete;

  // The datasets: N point numbers, M momentum numbers, and the observables' CSV columns
  // ("energy", "momentum0".."momentum{k-1}", "orthogonality"): columns that share a name but for
  // a trailing index form one dataset of that width.
  void header(int point_size, int momentum_size, const std::vector<std::string>& observable_columns);
  void row(double t, const double* q, int nq, const double* p, int np, const std::vector<double>& rest);
  // Appends the buffered rows and flushes the file.
  void flush();
  // flush(), then closes every object, checked.
  void close();

 private:
  struct Dataset {
    std::string name;
    int width = 1;      // numbers per row
    bool matrix = false;  // rows x width (else one number per row)
    long long id = -1;
    std::vector<double> pending;  // buffered rows, row-major
  };
  void create(Dataset& d);
  void append(Dataset& d);
  void release() noexcept;

  std::string name_;
  long long file_ = -1;
  std::vector<Dataset> datasets_;  // t, q, p, then the observables
  long long rows_ = 0, pending_rows_ = 0;
};

}  // namespace varia::host
