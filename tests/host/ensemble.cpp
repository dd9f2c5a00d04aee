// `varia ensemble` (spec "Tangent maps and ensembles"): the same datasets from threads and from
// mpirun's processes, each member's final state that of its own `varia run --set` to the bit,
// failures recorded per member, an interrupted ensemble resumed equal to a clean one, and bad
// flags refused with exit 2.
#include <doctest/doctest.h>
#include <hdf5.h>

#include <cmath>
#include <cstring>
#include <map>
#include <nlohmann/json.hpp>

#include "host/support.hpp"

namespace varia::test {
namespace {

using nlohmann::json;

// Every dataset of an ensemble file, as doubles (status converted), and its root attributes.
struct EnsembleData {
  std::map<std::string, std::vector<double>> datasets;
  std::string scene, vary;
};

std::string string_attribute(hid_t file, const char* name) {
  const hid_t attribute = H5Aopen(file, name, H5P_DEFAULT);
  const hid_t type = H5Aget_type(attribute);
  std::string text(H5Tget_size(type), '\0');
  H5Aread(attribute, type, text.data());
  H5Tclose(type);
  H5Aclose(attribute);
  return text.c_str();
}

EnsembleData read_ensemble(const fs::path& path) {
  EnsembleData data;
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  REQUIRE(file >= 0);
  data.scene = string_attribute(file, "scene");
  data.vary = string_attribute(file, "vary");
  H5Literate(
      file, H5_INDEX_NAME, H5_ITER_NATIVE, nullptr,
      [](hid_t group, const char* name, const H5L_info_t*, void* out) -> herr_t {
        const hid_t dataset = H5Dopen2(group, name, H5P_DEFAULT);
        const hid_t space = H5Dget_space(dataset);
        std::vector<double> values(static_cast<std::size_t>(H5Sget_simple_extent_npoints(space)));
        H5Dread(dataset, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data());
        H5Sclose(space);
        H5Dclose(dataset);
        static_cast<EnsembleData*>(out)->datasets[name] = values;
        return 0;
      },
      &data);
  H5Fclose(file);
  return data;
}

// Bit for bit, NaN equal to NaN.
bool same(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

void check_same(const EnsembleData& a, const EnsembleData& b) {
  CHECK(a.scene == b.scene);
  CHECK(a.vary == b.vary);
  REQUIRE(a.datasets.size() == b.datasets.size());
  for (const auto& [name, values] : a.datasets) {
    CAPTURE(name);
    CHECK(same(values, b.datasets.at(name)));
  }
}

const std::string kScene = "scenes/chaos/double-pendulum-megno.json --set /t_end=5 ";
const std::string kVaries = "--vary /initial/q/0=linspace:-3:3:4 --vary /initial/q/1=list:0.5,1,1.5,2,2.5,3,-1,-2 ";
const std::string kMpi = "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun --oversubscribe -n 3 ";

TEST_CASE("an ensemble of 32 members on 2 threads and under mpirun -n 3 gives identical datasets, each member's final "
          "state that of its own varia run --set to the bit") {
  TempDir dir;
  const auto threads = run_varia("ensemble " + kScene + kVaries + "--quiet --threads 2 --out '" +
                                 (dir / "threads.h5").string() + "'");
  CAPTURE(threads.err);
  REQUIRE(threads.code == 0);
  const auto processes = run_shell(kMpi + varia() + " ensemble " + kScene + kVaries + "--quiet --out " +
                                   quoted(dir / "mpi.h5"));
  CAPTURE(processes.err);
  REQUIRE(processes.code == 0);
  const EnsembleData a = read_ensemble(dir / "threads.h5"), b = read_ensemble(dir / "mpi.h5");
  check_same(a, b);
  const auto& parameters = a.datasets.at("parameters");
  REQUIRE(parameters.size() == 64);
  CHECK(parameters[0] == -3.0);  // the first --vary slowest
  CHECK(parameters[1] == 0.5);
  CHECK(parameters[3] == 1.0);
  CHECK(parameters[62] == 3.0);
  for (const char* name : {"status", "final_t", "final_q", "final_p", "energy_error_max", "megno_final",
                           "lyapunov_final"})
    CHECK_MESSAGE(a.datasets.count(name) == 1, name);
  for (int m = 0; m < 32; ++m) {
    CAPTURE(m);
    CHECK(a.datasets.at("status")[m] == 0);
    const auto single = run_varia("run " + kScene + "--quiet --set '/initial/q=[" +
                                  json(parameters[2 * m]).dump() + "," + json(parameters[2 * m + 1]).dump() +
                                  "]' --summary '" + (dir / "one.json").string() + "'");
    REQUIRE(single.code == 0);
    const json record = json::parse(read_file(dir / "one.json"));
    const auto q = record["final"]["q"].get<std::vector<double>>(), p = record["final"]["p"].get<std::vector<double>>();
    CHECK(same(q, {a.datasets.at("final_q")[2 * m], a.datasets.at("final_q")[2 * m + 1]}));
    CHECK(same(p, {a.datasets.at("final_p")[2 * m], a.datasets.at("final_p")[2 * m + 1]}));
    CHECK(record["megno_final"].get<double>() == a.datasets.at("megno_final")[m]);
  }
}

// Threads within processes: mpirun -n 2 with --threads 2 (rank 0's two threads and the other
// process's two, fed by its main thread) gives the same dataset as threads alone.
TEST_CASE("an ensemble under mpirun -n 2 with 2 threads a process gives the dataset of 2 threads") {
  TempDir dir;
  const auto threads = run_varia("ensemble " + kScene + kVaries + "--quiet --threads 2 --out '" +
                                 (dir / "threads.h5").string() + "'");
  REQUIRE(threads.code == 0);
  const auto hybrid = run_shell("OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun --oversubscribe -n 2 " +
                                varia() + " ensemble " + kScene + kVaries + "--quiet --threads 2 --out " +
                                quoted(dir / "hybrid.h5"));
  CAPTURE(hybrid.err);
  REQUIRE(hybrid.code == 0);
  const EnsembleData hybrid_data = read_ensemble(dir / "hybrid.h5");
  check_same(read_ensemble(dir / "threads.h5"), hybrid_data);
  for (double status : hybrid_data.datasets.at("status")) CHECK(status == 0);
}

TEST_CASE("a member that fails is recorded with its exit code and the rest run: exit 0") {
  TempDir dir;
  const auto outcome = run_varia("ensemble scenes/default.json --quiet --vary /step=list:0.1,5,0.2 --out '" +
                                 (dir / "e.h5").string() + "'");
  CHECK(outcome.code == 0);
  CHECK(contains(outcome.err, "member 1 (/step=5) exits 4: numerical failure"));
  const EnsembleData data = read_ensemble(dir / "e.h5");
  CHECK(data.datasets.at("status") == std::vector<double>{0, 4, 0});
  CHECK(std::isfinite(data.datasets.at("energy_error_max")[0]));
  const auto refused = run_varia("ensemble scenes/default.json --quiet --vary /step=list:0.1,50 --out '" +
                                 (dir / "r.h5").string() + "'");
  CHECK(refused.code == 0);
  CHECK(contains(refused.err, "member 1 (/step=50) exits 2: /t_end: expected a whole number of steps"));
  CHECK(read_ensemble(dir / "r.h5").datasets.at("status") == std::vector<double>{0, 2});
}

TEST_CASE("an ensemble interrupted with SIGINT exits 130 holding the members so far, and --resume completes it equal "
          "to a clean run") {
  TempDir dir;
  const std::string scene = "scenes/chaos/double-pendulum-megno.json --set /t_end=200 ";
  const std::string varies = "--vary /initial/q/0=linspace:1:2:4 --vary /initial/q/1=linspace:1:2:4 ";
  const std::string out = quoted(dir / "e.h5");
  // A background job of a non-interactive shell starts with SIGINT ignored (POSIX): env restores it.
  const auto interrupted = run_shell("env --default-signal=INT " + varia() + " ensemble " + scene + varies + "--quiet --out " + out +
                                     " & pid=$!; sleep 0.5; kill -INT $pid; wait $pid; echo \"exit $?\"");
  CAPTURE(interrupted.err);
  REQUIRE(contains(interrupted.out, "exit 130"));
  const EnsembleData partial = read_ensemble(dir / "e.h5");
  const auto& status = partial.datasets.at("status");
  const auto held = std::count_if(status.begin(), status.end(), [](double s) { return s >= 0; });
  CHECK(held > 0);
  CHECK(held < 16);
  const auto resumed = run_varia("ensemble " + scene + varies + "--quiet --resume --out " + out);
  CAPTURE(resumed.err);
  REQUIRE(resumed.code == 0);
  const auto clean = run_varia("ensemble " + scene + varies + "--quiet --threads 2 --out '" +
                               (dir / "clean.h5").string() + "'");
  REQUIRE(clean.code == 0);
  check_same(read_ensemble(dir / "e.h5"), read_ensemble(dir / "clean.h5"));
}

TEST_CASE("ensemble refuses bad specs, a plot without megno, and resuming another ensemble's file, exit 2") {
  TempDir dir;
  const std::string out = " --out '" + (dir / "e.h5").string() + "'";
  for (const char* bad : {"--vary step=list:1", "--vary /step=linspace:1:2", "--vary /step=list:1,x",
                          "--vary /step=uniform:0:1:0:1", "--vary /step=other:1"}) {
    CAPTURE(bad);
    const auto outcome = run_varia(std::string("ensemble scenes/default.json ") + bad + out);
    CHECK(outcome.code == 2);
    check_one_error_line(outcome, "--vary: expected");
  }
  const auto plot = run_varia("ensemble scenes/default.json --vary /step=list:0.1,0.2 --plot m.svg" + out);
  check_one_error_line(plot, "--plot: expected two --vary");
  REQUIRE(run_varia("ensemble scenes/default.json --quiet --vary /step=list:0.1,0.2" + out).code == 0);
  const auto other = run_varia("ensemble scenes/default.json --quiet --resume --vary /step=list:0.1,0.3" + out);
  CHECK(other.code == 2);
  check_one_error_line(other, "holds another ensemble");
  const auto suffix = run_varia("ensemble scenes/default.json --vary /step=list:0.1 --out e.csv");
  check_one_error_line(suffix, "--out: expected a file name ending in .h5");
}

TEST_CASE("uniform specs are reproducible: the same seed, the same values") {
  TempDir dir;
  for (const char* name : {"a.h5", "b.h5"})
    REQUIRE(run_varia(std::string("ensemble scenes/default.json --quiet --set /t_end=1 --vary "
                                  "/initial/q/0=uniform:0.5:1.5:5:42 --out '") +
                      (dir / name).string() + "'")
                .code == 0);
  const auto a = read_ensemble(dir / "a.h5").datasets.at("parameters");
  CHECK(same(a, read_ensemble(dir / "b.h5").datasets.at("parameters")));
  for (double x : a) CHECK((x >= 0.5 && x < 1.5));
}

}  // namespace
}  // namespace varia::test
