#include "hdf5_output.hpp"

#include <fcntl.h>
#include <hdf5.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fmt/format.h>

#include <cctype>
#include <cerrno>
#include <cstring>

#include "crash.hpp"
#include "errors.hpp"

namespace varia::host {

namespace {

constexpr hsize_t kBlockRows = 1024;  // rows per append, and the datasets' chunk length

}  // namespace

std::string hdf5_cause() {
  std::string description;
  const auto innermost = [](unsigned n, const H5E_error2_t* error, void* data) -> herr_t {
    if (n == 0 && error->desc != nullptr) *static_cast<std::string*>(data) = error->desc;
    return 0;
  };
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, innermost, &description);
  constexpr std::string_view kQuote = "error message = '";
  if (const auto at = description.find(kQuote); at != std::string::npos) {
    const auto from = at + kQuote.size();
    return description.substr(from, description.find('\'', from) - from);
  }
  return description.empty() ? "the HDF5 library gives no reason" : description;
}

Hdf5Writer::Lock::Lock(const std::filesystem::path& file) {
  fd_ = ::open(file.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd_ < 0) {
    if (errno == ENOENT) return;  // a new file: nothing to destroy
    throw OutputError(fmt::format("--out {}: cannot be opened: {}", file.string(), std::strerror(errno)));
  }
  struct stat status {};
  if (::fstat(fd_, &status) != 0 || !S_ISREG(status.st_mode)) {
    ::close(fd_);
    throw OutputError(fmt::format("--out {}: is not a regular file; expected an HDF5 file or a new name", file.string()));
  }
  try {
    lock_for_run(fd_, file, "--out",
                 "another run is writing this file, or a program holds it open through the HDF5 library");
  } catch (const OutputError&) {
    ::close(fd_);
    throw;
  }
}

Hdf5Writer::Lock::~Lock() {
  if (fd_ >= 0) ::close(fd_);
}

void take_over_hdf5() {
  H5dont_atexit();
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
}

long long create_hdf5_file(const std::string& path, std::string& cause) {
  const hid_t creation = H5Pcreate(H5P_FILE_CREATE), access = H5Pcreate(H5P_FILE_ACCESS);
  hid_t file = -1;
  if (creation >= 0 && access >= 0 && H5Pset_attr_phase_change(creation, 0, 0) >= 0 &&
      H5Pset_libver_bounds(access, H5F_LIBVER_V18, H5F_LIBVER_V18) >= 0)
    file = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, creation, access);
  if (file < 0) cause = hdf5_cause();  // before the calls below clear the library's error stack
  if (access >= 0) H5Pclose(access);
  if (creation >= 0) H5Pclose(creation);
  return file;
}

bool write_string_attribute(long long id, const char* name, const std::string& text, std::string& cause) {
  const hid_t type = H5Tcopy(H5T_C_S1);
  const hid_t space = H5Screate(H5S_SCALAR);
  hid_t attribute = -1;
  const bool written = type >= 0 && space >= 0 && H5Tset_size(type, text.size() + 1) >= 0 &&
                       (attribute = H5Acreate2(id, name, type, space, H5P_DEFAULT, H5P_DEFAULT)) >= 0 &&
                       H5Awrite(attribute, type, text.c_str()) >= 0;
  if (!written) cause = hdf5_cause();  // before the calls below clear the library's error stack
  if (attribute >= 0) H5Aclose(attribute);
  if (space >= 0) H5Sclose(space);
  if (type >= 0) H5Tclose(type);
  return written;
}

Hdf5Writer::Hdf5Writer(const std::filesystem::path& file, const std::string& scene_text)
    : name_(file.string()), lock_(file), staged_(file, "--out") {
  take_over_hdf5();
  try {
    create_file(scene_text);
  } catch (const OutputError&) {
    release();
    throw;
  }
  whole_ = 1;
  watch_trajectory(this);
}

// The file and its `scene` attribute, flushed.
void Hdf5Writer::create_file(const std::string& scene_text) {
  std::string cause;
  file_ = create_hdf5_file(staged_.temporary(), cause);
  if (file_ < 0) fail("created", cause);
  if (!write_string_attribute(file_, "scene", scene_text, cause)) fail("given the scene attribute", cause);
  if (H5Fflush(file_, H5F_SCOPE_GLOBAL) < 0) fail("flushed", hdf5_cause());
}

Hdf5Writer::~Hdf5Writer() {
  watch_trajectory(nullptr);
  if (!closed_ && !failed_) {
    try {
      close();  // the rows so far, e.g. of a run a plugin fault ended
    } catch (const OutputError&) {
    }
  }
  release();
}

void Hdf5Writer::release() noexcept {
  for (Dataset& d : datasets_)
    if (d.id >= 0) H5Dclose(d.id), d.id = -1;
  if (file_ >= 0) H5Fclose(file_), file_ = -1;
}

void Hdf5Writer::fail(const std::string& doing, const std::string& cause) {
  whole_ = 0;
  failed_ = true;
  throw OutputError(fmt::format("--out {}: cannot be {}: {}", name_, doing, printable(cause)));
}

// Observable columns "momentum0", "momentum1", ... share the dataset "momentum" (rows x k); a
// column without a trailing index is a dataset of one number per row.
void Hdf5Writer::header(int point_size, int momentum_size, const std::vector<std::string>& observable_columns) {
  datasets_ = {{"t", 1, false, -1, {}}, {"q", point_size, true, -1, {}}, {"p", momentum_size, true, -1, {}}};
  for (const std::string& column : observable_columns) {
    std::string base = column;
    while (!base.empty() && std::isdigit(static_cast<unsigned char>(base.back()))) base.pop_back();
    const bool indexed = base.size() < column.size();
    if (indexed && !datasets_.empty() && datasets_.back().name == base)
      ++datasets_.back().width;
    else
      datasets_.push_back({base, 1, indexed, -1, {}});
  }
  whole_ = 0;
  for (Dataset& d : datasets_) create(d);
  flush();
}

void Hdf5Writer::create(Dataset& d) {
  const int rank = d.matrix ? 2 : 1;
  const hsize_t dims[2] = {0, static_cast<hsize_t>(d.width)};
  const hsize_t max[2] = {H5S_UNLIMITED, static_cast<hsize_t>(d.width)};
  const hsize_t chunk[2] = {kBlockRows, static_cast<hsize_t>(d.width)};
  const hid_t space = H5Screate_simple(rank, dims, max);
  const hid_t properties = H5Pcreate(H5P_DATASET_CREATE);
  if (space >= 0 && properties >= 0 && H5Pset_chunk(properties, rank, chunk) >= 0)
    d.id = H5Dcreate2(file_, d.name.c_str(), H5T_NATIVE_DOUBLE, space, H5P_DEFAULT, properties, H5P_DEFAULT);
  const std::string cause = d.id < 0 ? hdf5_cause() : "";
  if (properties >= 0) H5Pclose(properties);
  if (space >= 0) H5Sclose(space);
  if (d.id < 0) fail(fmt::format("given the dataset '{}'", d.name), cause);
  d.pending.reserve(kBlockRows * static_cast<std::size_t>(d.width));
}

void Hdf5Writer::row(double t, const double* q, int nq, const double* p, int np, const std::vector<double>& rest) {
  datasets_[0].pending.push_back(t);
  datasets_[1].pending.insert(datasets_[1].pending.end(), q, q + nq);
  datasets_[2].pending.insert(datasets_[2].pending.end(), p, p + np);
  std::size_t k = 0;
  for (std::size_t d = 3; d < datasets_.size(); ++d)
    for (int c = 0; c < datasets_[d].width; ++c) datasets_[d].pending.push_back(rest[k++]);
  if (++pending_rows_ == static_cast<long long>(kBlockRows)) flush();
}

// Grows the dataset by the pending rows and writes them into the new hyperslab.
void Hdf5Writer::append(Dataset& d) {
  const int rank = d.matrix ? 2 : 1;
  const hsize_t size[2] = {static_cast<hsize_t>(rows_ + pending_rows_), static_cast<hsize_t>(d.width)};
  const hsize_t start[2] = {static_cast<hsize_t>(rows_), 0};
  const hsize_t count[2] = {static_cast<hsize_t>(pending_rows_), static_cast<hsize_t>(d.width)};
  bool written = H5Dset_extent(d.id, size) >= 0;
  const hid_t file_space = written ? H5Dget_space(d.id) : -1;
  const hid_t memory_space = H5Screate_simple(rank, count, nullptr);
  written = written && file_space >= 0 && memory_space >= 0 &&
            H5Sselect_hyperslab(file_space, H5S_SELECT_SET, start, nullptr, count, nullptr) >= 0 &&
            H5Dwrite(d.id, H5T_NATIVE_DOUBLE, memory_space, file_space, H5P_DEFAULT, d.pending.data()) >= 0;
  const std::string cause = written ? "" : hdf5_cause();
  if (memory_space >= 0) H5Sclose(memory_space);
  if (file_space >= 0) H5Sclose(file_space);
  if (!written) fail(fmt::format("written (dataset '{}')", d.name), cause);
  d.pending.clear();
}

void Hdf5Writer::flush() {
  if (file_ < 0 || failed_) return;
  whole_ = 0;
  if (pending_rows_ > 0) {
    for (Dataset& d : datasets_) append(d);
    rows_ += pending_rows_;
    pending_rows_ = 0;
  }
  if (H5Fflush(file_, H5F_SCOPE_GLOBAL) < 0) fail("flushed", hdf5_cause());
  whole_ = 1;
}

void Hdf5Writer::close() {
  if (failed_) throw OutputError(fmt::format("--out {}: cannot be closed after a failed write", name_));
  flush();
  whole_ = 0;
  closed_ = true;
  bool closed = true;
  for (Dataset& d : datasets_)
    if (d.id >= 0) closed = H5Dclose(d.id) >= 0 && closed, d.id = -1;
  if (file_ >= 0) closed = H5Fclose(file_) >= 0 && closed, file_ = -1;
  if (!closed) fail("closed", hdf5_cause());
  staged_.commit();
}

void Hdf5Writer::end_on_crash() noexcept { staged_.end_on_crash(whole_ != 0); }

}  // namespace varia::host
