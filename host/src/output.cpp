#include "output.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstring>
#include <optional>

#include <fmt/ranges.h>

#include "crash.hpp"
#include "errors.hpp"

namespace varia::host {

namespace fs = std::filesystem;

namespace {

constexpr std::size_t kFlushBytes = 1 << 16;  // write to the file in chunks of whole rows

std::FILE* results_stream = nullptr;  // keep_stdout_for_results()

// Writes all of `text` to `fd` (retrying short writes and interrupted calls); false with errno set
// when the system refuses part of it, `done` then telling how much it took.
bool write_all(int fd, std::string_view text, std::size_t& done) {
  done = 0;
  while (done < text.size()) {
    const ssize_t written = ::write(fd, text.data() + done, text.size() - done);
    if (written < 0 && errno == EINTR) continue;
    if (written <= 0) {
      if (written == 0) errno = EIO;
      return false;
    }
    done += static_cast<std::size_t>(written);
  }
  return true;
}

bool write_all(int fd, std::string_view text) {
  std::size_t done = 0;
  return write_all(fd, text, done);
}

[[noreturn]] void fail(std::string_view what, const fs::path& file, std::string_view doing, int error) {
  throw OutputError(fmt::format("{} {}: cannot be {}: {}", what, file.string(), doing, std::strerror(error)));
}

// The mode a new file gets from open(2) with 0666: what the umask leaves.
mode_t default_file_mode() {
  const mode_t mask = ::umask(0);
  ::umask(mask);
  return 0666 & ~mask;
}

// mkstemp's template for the temporary file beside `target`: "." + its name + ".tmp-XXXXXX", the
// name cut so that the whole stays a valid file name (at most NAME_MAX bytes) for every valid target.
std::string temporary_template(const fs::path& target) {
  constexpr std::string_view kSuffix = ".tmp-XXXXXX";
  const std::string name = target.filename().string().substr(0, NAME_MAX - 1 - kSuffix.size());
  const fs::path directory = target.has_parent_path() ? target.parent_path() : fs::path(".");
  return (directory / ("." + name + std::string(kSuffix))).string();
}

// The file that writing `file` replaces: `file` itself, or at the end of its symbolic links (also
// of a link naming a file that is not there yet), followed as open(2) follows them (at most 40).
fs::path link_target(const fs::path& file, std::string_view what) {
  constexpr int kMaxLinks = 40;
  fs::path target = file;
  for (int links = 0;; ++links) {
    std::error_code ec;
    if (!fs::is_symlink(fs::symlink_status(target, ec))) return target;
    if (links == kMaxLinks) fail(what, file, "written", ELOOP);
    const fs::path next = fs::read_symlink(target, ec);
    if (ec) fail(what, file, "written", ec.value());
    target = next.is_absolute() ? next : target.parent_path() / next;
  }
}

// A device or a pipe: written in place.
void write_in_place(const fs::path& file, std::string_view text, std::string_view what) {
  const int fd = ::open(file.c_str(), O_WRONLY | O_TRUNC | O_CLOEXEC);
  if (fd < 0) fail(what, file, "opened", errno);
  if (!write_all(fd, text)) {
    const int error = errno;
    ::close(fd);
    fail(what, file, "written", error);
  }
  if (::close(fd) != 0) fail(what, file, "written", errno);
}

// The identity of an existing file, or none.
std::optional<std::pair<dev_t, ino_t>> identity(const fs::path& file) {
  struct stat status {};
  if (::stat(file.c_str(), &status) != 0) return std::nullopt;
  return std::pair{status.st_dev, status.st_ino};
}

bool is_device(const fs::path& file) {
  struct stat status {};
  return ::stat(file.c_str(), &status) == 0 && (S_ISCHR(status.st_mode) || S_ISBLK(status.st_mode));
}

bool same_file(const fs::path& a, const fs::path& b) {
  if ((a == "-") != (b == "-")) return false;
  if (a == "-") return true;
  if (is_device(a) || is_device(b)) return false;
  const auto ia = identity(a), ib = identity(b);
  if (ia && ib) return *ia == *ib;
  std::error_code ec;
  return fs::weakly_canonical(a, ec) == fs::weakly_canonical(b, ec);
}

}  // namespace

StagedFile::StagedFile(const fs::path& file, std::string_view what)
    : what_(what), target_(link_target(file, what)), temporary_(temporary_template(target_)) {
  struct stat existing {};
  const bool exists = ::stat(target_.c_str(), &existing) == 0;
  fd_ = ::mkstemp(temporary_.data());
  if (fd_ < 0) fail(what_, target_, "written", errno);
  if (::fchmod(fd_, exists ? existing.st_mode & 07777 : default_file_mode()) != 0) abandon(errno);
}

StagedFile::~StagedFile() {
  if (committed_) return;
  if (fd_ >= 0) ::close(fd_);
  ::unlink(temporary_.c_str());
}

void StagedFile::abandon(int error) {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  ::unlink(temporary_.c_str());
  committed_ = true;  // nothing left to remove
  fail(what_, target_, "written", error);
}

void StagedFile::commit() {
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0) abandon(errno);
  if (::rename(temporary_.c_str(), target_.c_str()) != 0) abandon(errno);
  committed_ = true;
}

void StagedFile::end_on_crash(bool keep) noexcept {
  if (committed_) return;
  if (!keep || ::rename(temporary_.c_str(), target_.c_str()) != 0) ::unlink(temporary_.c_str());
}

void lock_for_run(int fd, const fs::path& file, std::string_view flag, std::string_view holders) {
  if (::flock(fd, LOCK_EX | LOCK_NB) == 0) return;
  const int error = errno;
  if (error == EWOULDBLOCK)
    throw OutputError(fmt::format("{} {}: {}; expected a file of its own", flag, file.string(), holders));
  fail(flag, file, "locked", error);
}

CsvWriter::CsvWriter(const fs::path& file) : name_(file.string()) {
  open(file);
  watch_trajectory(this);
}

void CsvWriter::open(const fs::path& file) {
  if (file == "-") {
    std::fflush(results());
    fd_ = ::fileno(results());
    return;
  }
  // Not truncated on opening: a file that another run is writing is refused before it is touched.
  fd_ = ::open(file.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC, 0666);
  if (fd_ < 0) fail("--out", file, "written", errno);
  owned_ = true;
  struct stat status {};
  regular_ = ::fstat(fd_, &status) == 0 && S_ISREG(status.st_mode);
  if (!regular_) return;
  try {
    lock_for_run(fd_, file, "--out", "another run is writing this file");
  } catch (const OutputError&) {
    ::close(fd_);
    throw;
  }
  if (::ftruncate(fd_, 0) != 0) {
    const int error = errno;
    ::close(fd_);
    fail("--out", file, "truncated", error);
  }
}

CsvWriter::~CsvWriter() {
  watch_trajectory(nullptr);
  if (fd_ < 0) return;
  try {
    flush();
  } catch (const OutputError&) {
  }
  if (owned_) ::close(fd_);
}

void CsvWriter::header(const std::vector<std::string>& columns) {
  fmt::format_to(std::back_inserter(buffer_), "{}", fmt::join(columns, ","));
  end_row();
}

void CsvWriter::row(double t, const double* a, int na, const double* b, int nb,
                    const std::vector<double>& rest) {
  auto out = std::back_inserter(buffer_);
  fmt::format_to(out, "{}", t);
  for (int i = 0; i < na; ++i) fmt::format_to(out, ",{}", a[i]);
  for (int i = 0; i < nb; ++i) fmt::format_to(out, ",{}", b[i]);
  for (double value : rest) fmt::format_to(out, ",{}", value);
  end_row();
}

void CsvWriter::end_row() {
  buffer_.push_back('\n');
  if (buffer_.size() >= kFlushBytes) flush();
}

void CsvWriter::flush() {
  if (failed_ || buffer_.size() == 0) return;
  const std::string_view rows(buffer_.data(), buffer_.size());
  int error = 0;
  const bool written = write_rows(rows, error);
  buffer_.clear();
  if (!written)
    throw OutputError(fmt::format("--out {}: cannot be written: {}; it ends with the last whole row written",
                                  name_, std::strerror(error)));
}

bool CsvWriter::write_rows(std::string_view rows, int& error) noexcept {
  std::size_t done = 0;
  if (write_all(fd_, rows, done)) {
    whole_ += static_cast<off_t>(rows.size());
    return true;
  }
  error = errno;
  failed_ = true;
  // A row cut part-way is taken back: the file keeps the whole rows that reached it.
  const auto last_newline = rows.substr(0, done).rfind('\n');
  if (regular_) (void)::ftruncate(fd_, whole_ + (last_newline == std::string_view::npos ? 0 : static_cast<off_t>(last_newline + 1)));
  return false;
}

void CsvWriter::end_on_crash() noexcept {
  if (fd_ < 0 || failed_) return;
  const auto last_newline = std::string_view(buffer_.data(), buffer_.size()).rfind('\n');
  int error = 0;
  if (last_newline != std::string_view::npos) (void)write_rows({buffer_.data(), last_newline + 1}, error);
}

void CsvWriter::close() {
  flush();
  const int fd = fd_;
  fd_ = -1;
  if (owned_ && ::close(fd) != 0) fail("--out", name_, "written", errno);
}

void write_output(const fs::path& file, std::string_view text, std::string_view what) {
  if (file == "-") {
    if (std::fwrite(text.data(), 1, text.size(), results()) != text.size() || std::fflush(results()) != 0)
      fail(what, "(stdout)", "written", errno);
    return;
  }
  std::error_code ec;
  const auto status = fs::status(file, ec);
  if (fs::exists(status) && !fs::is_regular_file(status)) return write_in_place(file, text, what);
  StagedFile staged(file, what);
  if (!write_all(staged.fd(), text)) fail(what, staged.target(), "written", errno);
  staged.commit();
}

std::string printable(std::string_view text) {
  std::string shown;
  for (const char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    if (byte < 0x20 || byte == 0x7f)
      shown += fmt::format("\\x{:02x}", byte);
    else
      shown += c;
  }
  return shown;
}

void write_json_file(const fs::path& file, const nlohmann::ordered_json& document, std::string_view what) {
  write_output(file, document.dump(2) + "\n", what);
}

std::FILE* results() { return results_stream != nullptr ? results_stream : stdout; }

void keep_stdout_for_results() {
  if (results_stream != nullptr || std::fflush(stdout) != 0) return;
  const int kept = ::fcntl(STDOUT_FILENO, F_DUPFD_CLOEXEC, 3);
  std::FILE* stream = kept < 0 ? nullptr : ::fdopen(kept, "w");
  if (stream == nullptr || ::dup2(STDERR_FILENO, STDOUT_FILENO) < 0) {
    if (stream != nullptr) std::fclose(stream);
    else if (kept >= 0) ::close(kept);
    throw OutputError(fmt::format("stdout cannot be kept apart from what plugins print: {}", std::strerror(errno)));
  }
  results_stream = stream;
}

void check_stdout() {
  if (std::fflush(results()) != 0 || std::ferror(results()))
    throw OutputError(fmt::format("stdout: the results cannot be written: {}", std::strerror(errno)));
}

void check_distinct(const std::vector<NamedFile>& inputs, const std::vector<NamedFile>& outputs) {
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    for (const NamedFile& input : inputs)
      if (input.file != "-" && same_file(outputs[i].file, input.file))
        throw InputError(fmt::format("{} {}: is the {} file; expected a file that is not read", outputs[i].flag,
                                     outputs[i].file.string(), input.flag));
    for (std::size_t j = 0; j < i; ++j)
      if (same_file(outputs[i].file, outputs[j].file))
        throw InputError(fmt::format("{} {}: is also the {} file; expected a file of its own", outputs[i].flag,
                                     outputs[i].file.string(), outputs[j].flag));
  }
}

}  // namespace varia::host
