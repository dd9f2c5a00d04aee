// The trajectory as HDF5 (spec "Outputs", `--out FILE.h5`), through the HDF5 C library from
// Debian: datasets `t` (rows), `q` (rows x N), `p` (rows x M) and one per observable (`energy`;
// `momentum` rows x k; `orthogonality`), rows as the CSV's, and the scene's JSON text as the
// root's attribute `scene` (stored densely, so a scene of any size fits: the file format of HDF5
// 1.8). The datasets are chunked and grow: rows are buffered and appended in blocks, and the file is
// flushed after each block.
//
// The file is written as a StagedFile (output.hpp): under a temporary name beside the target,
// renamed over it when the run ends, also early (exit 3, 4, an interruption: the rows so far), and,
// when a plugin ends the process, as it was at its last flush. A run refused or whose writes fail
// leaves the old file as it was. Every HDF5 call is checked: a failure throws OutputError naming
// the file and the cause HDF5 gives.
#pragma once

#include <csignal>
#include <filesystem>
#include <string>
#include <vector>

#include "output.hpp"

namespace varia::host {

// The cause HDF5 gives for the failure it just reported: its innermost error's description, or
// where that quotes the system's message ("error message = '...'"), that message. Read before any
// other call into the library, which clears its error stack.
std::string hdf5_cause();

// The process's use of the library: no clean-up at exit (it would flush a file whose write failed
// again, and HDF5 1.10 crashes closing it; every file is closed by its writer, or abandoned), and
// no error printing by the library (errors are reported by the writers, with hdf5_cause()).
void take_over_hdf5();
// A new file at `path` (truncated), its root's attributes stored densely (a text of any size
// fits), in the file format of HDF5 1.8; -1 on failure, with HDF5's `cause`.
long long create_hdf5_file(const std::string& path, std::string& cause);
// The string attribute `name` = `text` of the object `id` (the root: the file); false on failure,
// with HDF5's `cause`.
bool write_string_attribute(long long id, const char* name, const std::string& text, std::string& cause);

class Hdf5Writer final : public CrashSafeOutput {
 public:
  // Refuses (OutputError) a file that another run is writing or a program holds open through HDF5
  // (their lock), or that is not a regular file; then creates the temporary file with the `scene`
  // attribute.
  Hdf5Writer(const std::filesystem::path& file, const std::string& scene_text);
  // Unless close() was called: closes and renames the file when every write so far succeeded (the
  // rows so far), else removes it. Reports nothing: call close() to have errors reported.
  ~Hdf5Writer();
  Hdf5Writer(const Hdf5Writer&) = delete;
  Hdf5Writer& operator=(const Hdf5Writer&) = delete;

  // The datasets: N point numbers, M momentum numbers, and the observables' CSV columns
  // ("energy", "momentum0".."momentum{k-1}", "orthogonality"): columns that share a name but for
  // a trailing index form one dataset of that width.
  void header(int point_size, int momentum_size, const std::vector<std::string>& observable_columns);
  void row(double t, const double* q, int nq, const double* p, int np, const std::vector<double>& rest);
  // Appends the buffered rows and flushes the file.
  void flush();
  // flush(), closes every object, checked, and renames the file over the target.
  void close();
  // The file as it was at its last flush, renamed over the target; removed if a write was under
  // way. Only rename(2) or unlink(2).
  void end_on_crash() noexcept override;

 private:
  struct Dataset {
    std::string name;
    int width = 1;      // numbers per row
    bool matrix = false;  // rows x width (else one number per row)
    long long id = -1;
    std::vector<double> pending;  // buffered rows, row-major
  };
  // The target's lock, held for the run (none while the target does not exist).
  class Lock {
   public:
    explicit Lock(const std::filesystem::path& file);
    ~Lock();
    Lock(const Lock&) = delete;
    Lock& operator=(const Lock&) = delete;

   private:
    int fd_ = -1;
  };
  void create_file(const std::string& scene_text);
  void create(Dataset& d);
  void append(Dataset& d);
  void release() noexcept;
  [[noreturn]] void fail(const std::string& doing, const std::string& cause);

  std::string name_;
  Lock lock_;
  StagedFile staged_;
  long long file_ = -1;
  std::vector<Dataset> datasets_;  // t, q, p, then the observables
  long long rows_ = 0, pending_rows_ = 0;
  volatile std::sig_atomic_t whole_ = 0;  // the file on disk is as its last flush left it
  bool failed_ = false, closed_ = false;
};

}  // namespace varia::host
