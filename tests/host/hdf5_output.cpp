// `varia run --out FILE.h5` (spec "Outputs"): the datasets hold the CSV's rows, the root carries
// the scene, and a run that fails keeps the rows written before the failure readable.
#include <hdf5.h>

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
  CHECK(t.dims[0] == 11);  // steps 0..10: step 11 failed
  CHECK(t.values.back() == doctest::Approx(0.5));
}
