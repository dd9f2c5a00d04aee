#include "hdf5_output.hpp"

#include <hdf5.h>

#include <fmt/format.h>

#include <cctype>

#include "errors.hpp"

namespace varia::host {

namespace {

constexpr hsize_t kBlockRows = 1024;  // rows per append, and the datasets' chunk length

}  // namespace

Hdf5Writer::Hdf5Writer(const std::filesystem::path& file, const std::string& scene_text) : name_(file.string()) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // errors are reported here, not printed by the library
  file_ = H5Fcreate(name_.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  if (file_ < 0) throw OutputError(fmt::format("--out {}: cannot create the HDF5 file", name_));
  const hid_t type = H5Tcopy(H5T_C_S1);
  const hid_t space = H5Screate(H5S_SCALAR);
  hid_t attribute = -1;
  const bool written = type >= 0 && space >= 0 && H5Tset_size(type, scene_text.size() + 1) >= 0 &&
                       (attribute = H5Acreate2(file_, "scene", type, space, H5P_DEFAULT, H5P_DEFAULT)) >= 0 &&
                       H5Awrite(attribute, type, scene_text.c_str()) >= 0;
  if (attribute >= 0) H5Aclose(attribute);
  if (space >= 0) H5Sclose(space);
  if (type >= 0) H5Tclose(type);
  if (!written) {
    release();
    throw OutputError(fmt::format("--out {}: cannot write the scene attribute", name_));
  }
}

Hdf5Writer::~Hdf5Writer() { release(); }

void Hdf5Writer::release() noexcept {
  for (Dataset& d : datasets_)
    if (d.id >= 0) H5Dclose(d.id), d.id = -1;
  if (file_ >= 0) H5Fclose(file_), file_ = -1;
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
  for (Dataset& d : datasets_) create(d);
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
  if (properties >= 0) H5Pclose(properties);
  if (space >= 0) H5Sclose(space);
  if (d.id < 0) throw OutputError(fmt::format("--out {}: cannot create the dataset '{}'", name_, d.name));
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
  if (memory_space >= 0) H5Sclose(memory_space);
  if (file_space >= 0) H5Sclose(file_space);
  if (!written) throw OutputError(fmt::format("--out {}: cannot write the dataset '{}'", name_, d.name));
  d.pending.clear();
}

void Hdf5Writer::flush() {
  if (file_ < 0) return;
  if (pending_rows_ > 0) {
    for (Dataset& d : datasets_) append(d);
    rows_ += pending_rows_;
    pending_rows_ = 0;
  }
  if (H5Fflush(file_, H5F_SCOPE_GLOBAL) < 0) throw OutputError(fmt::format("--out {}: cannot flush the file", name_));
}

void Hdf5Writer::close() {
  flush();
  bool closed = true;
  for (Dataset& d : datasets_)
    if (d.id >= 0) closed = H5Dclose(d.id) >= 0 && closed, d.id = -1;
  if (file_ >= 0) closed = H5Fclose(file_) >= 0 && closed, file_ = -1;
  if (!closed) throw OutputError(fmt::format("--out {}: cannot close the file", name_));
}

}  // namespace varia::host
