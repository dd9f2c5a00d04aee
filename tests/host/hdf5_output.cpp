// `varia run --out FILE.h5` (spec "Outputs"): the datasets hold the CSV's rows, the root carries
// the scene, and a run that fails keeps the rows written before the failure readable. A run refused
// or whose writes fail leaves the old file as it was; a plugin crash leaves a readable file
// (issue 43, item 8).
#include <fcntl.h>
#include <hdf5.h>
#include <sys/file.h>

#include <doctest/doctest.h>

#include <nlohmann/json.hpp>
#include <sstream>

#include "support.hpp"

using namespace varia::test;
using nlohmann::json;

namespace {

// A dataset's numbers (row-major) and its dimensions, read through the HDF5 C library.
struct Dataset {
  std::vector<double> values;
  std::vector<hsize_t> dims;
};

Dataset read_dataset(hid_t file, const char* name) {
  Dataset d;
  const hid_t set = H5Dopen2(file, name, H5P_DEFAULT);
  REQUIRE(set >= 0);
  const hid_t space = H5Dget_space(set);
  d.dims.resize(static_cast<std::size_t>(H5Sget_simple_extent_ndims(space)));
  H5Sget_simple_extent_dims(space, d.dims.data(), nullptr);
  hsize_t count = 1;
  for (hsize_t n : d.dims) count *= n;
  d.values.resize(count);
  if (count > 0) CHECK(H5Dread(set, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, d.values.data()) >= 0);
  H5Sclose(space);
  H5Dclose(set);
  return d;
}

std::string read_scene(hid_t file) {
  const hid_t attribute = H5Aopen(file, "scene", H5P_DEFAULT);
  REQUIRE(attribute >= 0);
  const hid_t type = H5Aget_type(attribute);
  std::string text(H5Tget_size(type), '\0');
  CHECK(H5Aread(attribute, type, text.data()) >= 0);
  H5Tclose(type);
  H5Aclose(attribute);
  return text.c_str();  // without the terminating null
}

// The CSV's numbers, row by row.
std::vector<std::vector<double>> csv_rows(const std::string& text) {
  std::vector<std::vector<double>> rows;
  const auto lines = lines_of(text);
  for (std::size_t i = 1; i < lines.size(); ++i) {
    std::vector<double> row;
    std::stringstream cells(lines[i]);
    for (std::string cell; std::getline(cells, cell, ',');) row.push_back(std::stod(cell));
    rows.push_back(row);
  }
  return rows;
}

// The rows of `t` in an HDF5 trajectory, or -1 when the file cannot be read as one.
long long rows_of(const fs::path& h5) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const hid_t file = H5Fopen(h5.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (file < 0) return -1;
  const hid_t set = H5Dopen2(file, "t", H5P_DEFAULT);
  hsize_t rows = 0;
  const hid_t space = set < 0 ? -1 : H5Dget_space(set);
  const bool read = space >= 0 && H5Sget_simple_extent_dims(space, &rows, nullptr) == 1;
  if (space >= 0) H5Sclose(space);
  if (set >= 0) H5Dclose(set);
  H5Fclose(file);
  return read ? static_cast<long long>(rows) : -1;
}

// Nothing but `names` in the directory: no temporary file left beside the output.
void check_only(const fs::path& directory, std::vector<std::string> names) {
  std::vector<std::string> found;
  for (const auto& entry : fs::directory_iterator(directory)) found.push_back(entry.path().filename().string());
  std::sort(found.begin(), found.end());
  std::sort(names.begin(), names.end());
  CHECK(found == names);
}

}  // namespace

TEST_CASE("run --out FILE.h5 writes t, q, p and each observable with the CSV's rows, and the scene as an attribute") {
  TempDir dir;
  json scene = json::parse(read_file(kSourceDir / "scenes" / "kepler-galerkin.json"));
  scene["output"] = {{"every", 7}};
  write_file(dir / "scene.json", scene.dump());
  const std::string run = "run '" + (dir / "scene.json").string() + "' --quiet --out '";
  REQUIRE(run_varia(run + (dir / "t.csv").string() + "'").code == 0);
  REQUIRE(run_varia(run + (dir / "t.h5").string() + "'").code == 0);
  const auto rows = csv_rows(read_file(dir / "t.csv"));
  const hid_t file = H5Fopen((dir / "t.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  REQUIRE(file >= 0);
  CHECK(json::parse(read_scene(file)) == scene);
  // CSV columns: t, q0 q1, p0 p1, energy, momentum0.
  const Dataset t = read_dataset(file, "t"), q = read_dataset(file, "q"), p = read_dataset(file, "p"),
                energy = read_dataset(file, "energy"), momentum = read_dataset(file, "momentum");
  H5Fclose(file);
  REQUIRE(t.dims == std::vector<hsize_t>{rows.size()});
  CHECK(q.dims == std::vector<hsize_t>{rows.size(), 2});
  CHECK(p.dims == std::vector<hsize_t>{rows.size(), 2});
  CHECK(energy.dims == std::vector<hsize_t>{rows.size()});
  CHECK(momentum.dims == std::vector<hsize_t>{rows.size(), 1});
  for (std::size_t k = 0; k < rows.size(); ++k) {
    CAPTURE(k);
    REQUIRE(rows[k].size() == 7);
    CHECK(t.values[k] == rows[k][0]);
    CHECK(q.values[2 * k] == rows[k][1]);
    CHECK(q.values[2 * k + 1] == rows[k][2]);
    CHECK(p.values[2 * k] == rows[k][3]);
    CHECK(p.values[2 * k + 1] == rows[k][4]);
    CHECK(energy.values[k] == rows[k][5]);
    CHECK(momentum.values[k] == rows[k][6]);
  }
}

TEST_CASE("run --out FILE.h5 that fails (exit 4) leaves the rows before the failure readable") {
  TempDir dir;
  const auto outcome = run_varia("run '" + (kSourceDir / "scenes" / "hard" / "fpu-unstable.json").string() +
                                 "' --quiet --out '" + (dir / "t.h5").string() + "'");
  CHECK(outcome.code == 4);
  const hid_t file = H5Fopen((dir / "t.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  REQUIRE(file >= 0);
  const Dataset t = read_dataset(file, "t");
  H5Fclose(file);
  REQUIRE(t.dims.size() == 1);
  CHECK(t.dims[0] == 2);  // steps 0 and 1: at step 2 the energy error exceeds the energy's scale
  CHECK(t.values.back() == doctest::Approx(0.05));
}

TEST_CASE("run --out FILE.h5 on a file another run writes or a reader holds open is refused, the file kept whole") {
  TempDir dir;
  const fs::path h5 = dir / "t.h5";
  REQUIRE(run_varia("run scenes/default.json --quiet --out " + quoted(h5)).code == 0);
  REQUIRE(rows_of(h5) == 201);
  for (const bool reader : {false, true}) {
    CAPTURE(reader);
    // Another run holds its lock, or an HDF5 reader holds the library's (shared) lock.
    const int fd = reader ? -1 : ::open(h5.c_str(), O_RDONLY);
    if (!reader) REQUIRE(::flock(fd, LOCK_EX) == 0);
    const hid_t open = reader ? H5Fopen(h5.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT) : -1;
    if (reader) REQUIRE(open >= 0);
    const auto outcome = run_varia("run scenes/kepler-galerkin.json --quiet --out " + quoted(h5));
    if (reader) H5Fclose(open);
    else ::close(fd);
    CHECK(outcome.code == 2);
    check_one_error_line(outcome, "--out " + h5.string() + ": another run is writing this file, or a program holds "
                                                           "it open through the HDF5 library");
    CHECK(rows_of(h5) == 201);
    check_only(dir.path(), {"t.h5"});
  }
}

TEST_CASE("run --out FILE.h5 whose writes fail names the cause, exit 2, and leaves the old file as it was") {
  TempDir dir;
  const fs::path h5 = dir / "t.h5";
  REQUIRE(run_varia("run scenes/default.json --quiet --out " + quoted(h5)).code == 0);
  REQUIRE(rows_of(h5) == 201);
  json scene = json::parse(read_file(kSourceDir / "scenes" / "default.json"));
  scene["t_end"] = 1000;  // 10,000 rows: blocks of 8 KiB a dataset
  write_file(dir / "long.json", scene.dump());
  // A file size limit (SIGXFSZ ignored) refuses writes past 40 blocks (of 512 or 1024 bytes), as
  // a full disk does: past the file's header, inside its first block of rows.
  const auto outcome = run_shell("trap '' XFSZ; ulimit -f 40; " + varia::test::varia() + " run " + quoted(dir / "long.json") +
                                 " --quiet --out " + quoted(h5));
  CHECK(outcome.code == 2);
  check_one_error_line(outcome, "--out " + h5.string() + ": cannot be ");
  CHECK(contains(outcome.err, "File too large"));
  CHECK(rows_of(h5) == 201);
  check_only(dir.path(), {"long.json", "t.h5"});
}

TEST_CASE("run --out FILE.h5 keeps a scene text over 64 KiB as the scene attribute") {
  TempDir dir;
  json scene = json::parse(read_file(kSourceDir / "scenes" / "default.json"));
  scene["description"] = std::string(100000, 'd');
  write_file(dir / "s.json", scene.dump());
  const auto outcome = run_varia("run " + quoted(dir / "s.json") + " --quiet --out " + quoted(dir / "t.h5"));
  CAPTURE(outcome.err);
  REQUIRE(outcome.code == 0);
  const hid_t file = H5Fopen((dir / "t.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  REQUIRE(file >= 0);
  CHECK(json::parse(read_scene(file)) == scene);
  H5Fclose(file);
}

TEST_CASE("a plugin crash during run --out FILE.h5 leaves a readable file: the rows of the blocks flushed") {
  TempDir dir;
  fs::copy_file(fs::path(VARIA_FAULT_PLUGIN_DIR) / "fault_segfaults.so", dir / "fault_segfaults.so");
  // Six evaluations a step: the crash comes before the first block of 1024 rows, or after two.
  for (const auto& [after, rows] : {std::pair{300L, 0LL}, std::pair{18000L, 2048LL}}) {
    CAPTURE(after);
    json scene = json::parse(read_file(kSourceDir / "scenes" / "default.json"));
    scene["system"]["lagrangian"] = {{"type", "fault-segfault"}, {"after", after}};
    scene.erase("observe");
    scene.erase("t_end");
    scene["steps"] = 4000;
    write_file(dir / "s.json", scene.dump());
    const auto outcome = run_varia("run " + quoted(dir / "s.json") + " --quiet --out " + quoted(dir / "t.h5") +
                                   " --plugin-path " + quoted(dir.path()));
    CHECK(outcome.code == 3);
    CHECK(rows_of(dir / "t.h5") == rows);
    check_only(dir.path(), {"fault_segfaults.so", "s.json", "t.h5"});
  }
}
