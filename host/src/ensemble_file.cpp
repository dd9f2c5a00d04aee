#include "ensemble_file.hpp"

#include <hdf5.h>

#include <fmt/format.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <system_error>

#include "errors.hpp"
#include "hdf5_output.hpp"

namespace varia::host {

namespace fs = std::filesystem;

// The file and its datasets: parameters, status, final_t, final_q, final_p, then the numbers.
struct EnsembleFile::Handles {
  hid_t file = -1;
  std::vector<hid_t> datasets;
  ~Handles() {
    for (hid_t d : datasets)
      if (d >= 0) H5Dclose(d);
    if (file >= 0) H5Fclose(file);
  }
};

namespace {

std::vector<std::string> dataset_names(const EnsembleLayout& layout) {
  std::vector<std::string> names{"parameters", "status", "final_t", "final_q", "final_p"};
  names.insert(names.end(), layout.numbers.begin(), layout.numbers.end());
  return names;
}

int width_of(const EnsembleLayout& layout, std::size_t dataset) {
  switch (dataset) {
    case 0: return layout.varies;
    case 3: return layout.point_size;
    case 4: return layout.dim;
    default: return 1;
  }
}

bool matrix(std::size_t dataset) { return dataset == 0 || dataset == 3 || dataset == 4; }

std::string read_string_attribute(hid_t file, const char* name) {
  if (H5Aexists(file, name) <= 0) return {};
  const hid_t attribute = H5Aopen(file, name, H5P_DEFAULT);
  const hid_t type = attribute >= 0 ? H5Aget_type(attribute) : -1;
  std::string text;
  if (type >= 0) {
    text.resize(H5Tget_size(type));
    if (H5Aread(attribute, type, text.data()) < 0) text.clear();
    text.resize(std::strlen(text.c_str()));
  }
  if (type >= 0) H5Tclose(type);
  if (attribute >= 0) H5Aclose(attribute);
  return text;
}

// One row (member) of a dataset of `width` numbers per row.
bool write_row(hid_t dataset, hid_t type, bool is_matrix, long row, int width, const void* data, std::string& cause) {
  const int rank = is_matrix ? 2 : 1;
  const hsize_t start[2] = {static_cast<hsize_t>(row), 0}, count[2] = {1, static_cast<hsize_t>(width)};
  const hid_t file_space = H5Dget_space(dataset);
  const hid_t memory_space = H5Screate_simple(rank, count, nullptr);
  const bool written = file_space >= 0 && memory_space >= 0 &&
                       H5Sselect_hyperslab(file_space, H5S_SELECT_SET, start, nullptr, count, nullptr) >= 0 &&
                       H5Dwrite(dataset, type, memory_space, file_space, H5P_DEFAULT, data) >= 0;
  if (!written) cause = hdf5_cause();  // before the calls below clear the library's error stack
  if (memory_space >= 0) H5Sclose(memory_space);
  if (file_space >= 0) H5Sclose(file_space);
  return written;
}

}  // namespace

EnsembleFile::EnsembleFile(const fs::path& file, const std::string& scene_text, const std::string& vary_text,
                           const EnsembleLayout& layout, const std::vector<double>& parameters, bool resume)
    : name_(file.string()), layout_(layout), h_(std::make_unique<Handles>()) {
  take_over_hdf5();
  const bool existing = resume && fs::exists(file);
  staged_ = std::make_unique<StagedFile>(file, "--out");
  if (existing) open_copy(scene_text, vary_text);
  else create(scene_text, vary_text, parameters);
}

EnsembleFile::~EnsembleFile() = default;  // without close(): the staged copy is removed, the target stays

void EnsembleFile::fail(const std::string& doing, const std::string& cause) {
  throw OutputError(fmt::format("--out {}: cannot be {}: {}", name_, doing, printable(cause)));
}

void EnsembleFile::create(const std::string& scene_text, const std::string& vary_text,
                          const std::vector<double>& parameters) {
  std::string cause;
  h_->file = create_hdf5_file(staged_->temporary(), cause);
  if (h_->file < 0) fail("created", cause);
  if (!write_string_attribute(h_->file, "scene", scene_text, cause) ||
      !write_string_attribute(h_->file, "vary", vary_text, cause))
    fail("given its attributes", cause);
  const auto names = dataset_names(layout_);
  for (std::size_t d = 0; d < names.size(); ++d) {
    const hsize_t dims[2] = {static_cast<hsize_t>(layout_.members), static_cast<hsize_t>(width_of(layout_, d))};
    const hid_t space = H5Screate_simple(matrix(d) ? 2 : 1, dims, nullptr);
    const hid_t properties = H5Pcreate(H5P_DATASET_CREATE);
    const bool status = d == 1;
    const int not_run = -1;
    const double missing = std::nan("");
    const hid_t type = status ? H5T_NATIVE_INT32 : H5T_NATIVE_DOUBLE;
    hid_t id = -1;
    if (space >= 0 && properties >= 0 &&
        H5Pset_fill_value(properties, type, status ? static_cast<const void*>(&not_run) : &missing) >= 0 &&
        H5Pset_alloc_time(properties, H5D_ALLOC_TIME_EARLY) >= 0)
      id = H5Dcreate2(h_->file, names[d].c_str(), type, space, H5P_DEFAULT, properties, H5P_DEFAULT);
    const std::string why = id < 0 ? hdf5_cause() : "";
    if (properties >= 0) H5Pclose(properties);
    if (space >= 0) H5Sclose(space);
    if (id < 0) fail(fmt::format("given the dataset '{}'", names[d]), why);
    h_->datasets.push_back(id);
  }
  if (layout_.varies > 0 &&
      H5Dwrite(h_->datasets[0], H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, parameters.data()) < 0)
    fail("written (dataset 'parameters')", hdf5_cause());
  statuses_.assign(static_cast<std::size_t>(layout_.members), -1);
  if (H5Fflush(h_->file, H5F_SCOPE_GLOBAL) < 0) fail("flushed", hdf5_cause());
}

// --resume: the target copied to the temporary name, opened there, the same ensemble's.
void EnsembleFile::open_copy(const std::string& scene_text, const std::string& vary_text) {
  std::error_code error;
  fs::copy_file(staged_->target(), staged_->temporary(), fs::copy_options::overwrite_existing, error);
  if (error) fail("copied to resume it", error.message());
  h_->file = H5Fopen(staged_->temporary().c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  if (h_->file < 0) fail("opened to resume it", hdf5_cause());
  if (read_string_attribute(h_->file, "scene") != scene_text || read_string_attribute(h_->file, "vary") != vary_text)
    throw OutputError(fmt::format("--resume: {} holds another ensemble (its scene or its --vary specs differ); "
                                  "expected the file of this scene and these specs, or a new name",
                                  printable(name_)));
  for (const auto& name : dataset_names(layout_)) {
    const hid_t id = H5Dopen2(h_->file, name.c_str(), H5P_DEFAULT);
    if (id < 0) fail(fmt::format("resumed: it has no dataset '{}'", name), hdf5_cause());
    h_->datasets.push_back(id);
  }
  statuses_.assign(static_cast<std::size_t>(layout_.members), -1);
  const hid_t space = H5Dget_space(h_->datasets[1]);
  const hssize_t points = space >= 0 ? H5Sget_simple_extent_npoints(space) : -1;
  if (space >= 0) H5Sclose(space);
  if (points != layout_.members)
    throw OutputError(fmt::format("--resume: {} holds {} members; this ensemble has {}", printable(name_), points,
                                  layout_.members));
  if (H5Dread(h_->datasets[1], H5T_NATIVE_INT32, H5S_ALL, H5S_ALL, H5P_DEFAULT, statuses_.data()) < 0)
    fail("read (dataset 'status')", hdf5_cause());
}

void EnsembleFile::write(long member, const MemberResult& r) {
  const std::int32_t status = r.status;
  std::string cause;
  bool written = write_row(h_->datasets[1], H5T_NATIVE_INT32, false, member, 1, &status, cause) &&
                 write_row(h_->datasets[2], H5T_NATIVE_DOUBLE, false, member, 1, &r.t, cause);
  if (written && static_cast<int>(r.q.size()) == layout_.point_size)
    written = write_row(h_->datasets[3], H5T_NATIVE_DOUBLE, true, member, layout_.point_size, r.q.data(), cause);
  if (written && static_cast<int>(r.p.size()) == layout_.dim)
    written = write_row(h_->datasets[4], H5T_NATIVE_DOUBLE, true, member, layout_.dim, r.p.data(), cause);
  for (std::size_t k = 0; written && k < r.numbers.size(); ++k)
    written = write_row(h_->datasets[5 + k], H5T_NATIVE_DOUBLE, false, member, 1, &r.numbers[k], cause);
  if (!written) fail(fmt::format("written (member {})", member), cause);
  statuses_[static_cast<std::size_t>(member)] = r.status;
}

std::vector<double> EnsembleFile::numbers(const std::string& key) const {
  std::vector<double> values(static_cast<std::size_t>(layout_.members));
  for (std::size_t k = 0; k < layout_.numbers.size(); ++k)
    if (layout_.numbers[k] == key &&
        H5Dread(h_->datasets[5 + k], H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()) >= 0)
      return values;
  throw OutputError(fmt::format("--out {}: cannot be read (dataset '{}'): {}", name_, key, hdf5_cause()));
}

void EnsembleFile::close() {
  if (closed_) return;
  closed_ = true;
  bool closed = H5Fflush(h_->file, H5F_SCOPE_GLOBAL) >= 0;
  for (hid_t& d : h_->datasets) closed = H5Dclose(d) >= 0 && closed, d = -1;
  closed = H5Fclose(h_->file) >= 0 && closed;
  h_->file = -1;
  if (!closed) fail("closed", hdf5_cause());
  staged_->commit();
}

}  // namespace varia::host
