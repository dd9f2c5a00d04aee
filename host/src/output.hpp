// Output files (spec: "Outputs"). Every write and close is checked: a failure throws OutputError
// naming the file. The trajectory CSV is written in whole rows, so that the file ends with a whole
// row on every exit path (a write that fails part-way is cut back to the last whole row); JSON
// documents and plots are written to a temporary file beside the target and renamed over it, so a
// reader sees the old file or the new one, never a part (docs/security.md, "Outputs").
#pragma once

#include <sys/types.h>

#include <Eigen/Core>
#include <cstdio>
#include <filesystem>
#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace varia::host {

// A trajectory output that the crash handlers (crash.hpp) leave whole when a plugin ends the
// process. end_on_crash() may only make async-signal-safe calls.
class CrashSafeOutput {
 public:
  virtual void end_on_crash() noexcept = 0;

 protected:
  ~CrashSafeOutput() = default;
};

// A file written under a temporary name beside its target and renamed over the target when whole,
// so that a reader sees the old file or the new one, never a part, and a run that fails before
// commit() leaves the old file as it was. A symbolic link keeps pointing where it did, also when
// what it names is not there yet: the file it names is replaced. The temporary file has the mode of
// the file it replaces (a new one: what the umask leaves of 0666).
class StagedFile {
 public:
  // Creates the temporary file. `what` names the output in messages (e.g. "--summary"). Throws
  // OutputError.
  StagedFile(const std::filesystem::path& file, std::string_view what);
  ~StagedFile();  // removes the temporary file unless it was committed
  StagedFile(const StagedFile&) = delete;
  StagedFile& operator=(const StagedFile&) = delete;

  int fd() const { return fd_; }  // open on the temporary file until commit()
  const std::string& temporary() const { return temporary_; }
  const std::filesystem::path& target() const { return target_; }  // at the end of the links
  // Closes the descriptor (checked) and renames the temporary file over the target. Throws
  // OutputError (the temporary file then removed).
  void commit();
  // For the crash handlers: renames the temporary file over the target (keep), or removes it.
  // Only rename(2) or unlink(2), which are async-signal-safe.
  void end_on_crash(bool keep) noexcept;

 private:
  [[noreturn]] void abandon(int error);
  std::string what_;
  std::filesystem::path target_;
  std::string temporary_;
  int fd_ = -1;
  bool committed_ = false;
};

// Locks the open regular file `fd` (named `file` as `flag`) for this run, without waiting: a second
// run writing the same file is refused (OutputError naming `holders`, who may hold it) before it
// touches the file.
void lock_for_run(int fd, const std::filesystem::path& file, std::string_view flag, std::string_view holders);

class CsvWriter final : public CrashSafeOutput {
 public:
  // "-" writes to stdout (results()). A regular file is locked for the run: a second run writing the same
  // file is refused (OutputError) before it truncates it. Throws OutputError when the file
  // cannot be opened.
  explicit CsvWriter(const std::filesystem::path& file);
  ~CsvWriter();  // writes what is buffered, ignoring errors: call close() to have them reported
  CsvWriter(const CsvWriter&) = delete;
  CsvWriter& operator=(const CsvWriter&) = delete;

  void header(const std::vector<std::string>& columns);
  // One row of numbers at full precision (the shortest text that reads back to the same double);
  // it reaches the file whole.
  void row(double t, const double* a, int na, const double* b, int nb, const std::vector<double>& rest);
  // Writes the buffered rows. Throws OutputError when they cannot all be written; the file then
  // ends with the last whole row written before.
  void flush();
  // flush(), then closes the file, checked.
  void close();
  // Writes the buffered whole rows, reporting nothing: for the crash handlers (crash.hpp), when a
  // plugin ends the process. It only calls write(2) and ftruncate(2), which are async-signal-safe.
  void end_on_crash() noexcept override;

 private:
  void open(const std::filesystem::path& file);
  void end_row();
  // Writes `rows` (whole rows); false with the error when the system refuses part of it, the file
  // then cut back to its last whole row.
  bool write_rows(std::string_view rows, int& error) noexcept;
  std::string name_;
  int fd_ = -1;
  bool owned_ = false, regular_ = false, failed_ = false;
  off_t whole_ = 0;  // bytes written that end with a whole row
  fmt::memory_buffer buffer_;
};

inline std::vector<double> as_vector(const Eigen::VectorXd& x) { return {x.data(), x.data() + x.size()}; }

// Writes `text` to `file` ("-": stdout): a regular file (or a new one) through a StagedFile,
// anything else (a device, a pipe) directly. `what` names the output in messages (e.g.
// "--summary"). Throws OutputError.
void write_output(const std::filesystem::path& file, std::string_view text, std::string_view what);

// `text` as a terminal or a one-line message may show it: control characters (newlines, terminal
// escapes, NUL) written as \xNN, so that text from a scene or a file name can neither move the
// cursor, nor end a line, nor cut a message short.
std::string printable(std::string_view text);

// Writes a JSON document (pretty-printed) through write_output.
void write_json_file(const std::filesystem::path& file, const nlohmann::ordered_json& document,
                     std::string_view what = "output");

// Where results meant for stdout go (spec: "results go to files or stdout"): stdout itself, or,
// after keep_stdout_for_results(), a stream of its own on the real stdout.
std::FILE* results();

// Keeps stdout for results: the real stdout is duplicated for results(), and descriptor 1 (with
// the C library's stdout and std::cout, which plugins share with varia) is pointed at stderr, so
// that what plugins print goes to stderr and cannot corrupt a CSV or a JSON document on stdout
// (docs/security.md). Called once, before any plugin is loaded.
void keep_stdout_for_results();

// Flushes and checks results(): results written there that did not arrive are an OutputError.
void check_stdout();

// A file a command reads or writes, as named on its command line ("-": stdin or stdout).
struct NamedFile {
  std::string flag;  // e.g. "--out", or "SCENE" for an input
  std::filesystem::path file;
};

// Refuses (InputError) an output that is one of the inputs or another output: the same path, the
// same file under another name, or stdout twice. Devices (/dev/null) may be named more than once.
void check_distinct(const std::vector<NamedFile>& inputs, const std::vector<NamedFile>& outputs);

}  // namespace varia::host
