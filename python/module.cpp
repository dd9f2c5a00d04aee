// The extension `varia._varia` (docs/python.md): the host's commands as functions over a scene
// (a JSON text or a file), on the same core and the same code paths as the CLI (run_scene,
// verify_scene, the discrete Lagrangian), so a run's numbers are the CLI's to the bit. Results
// cross as numpy arrays (the trajectory, filled row by row as the run writes them) and JSON texts
// (records, checks); every failure raises `_varia.Failure` whose text is a JSON object saying what
// it was, which varia/__init__.py turns into SceneError, NumericalFailure or PluginFault.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <boost/dll/runtime_symbol_info.hpp>
#include <cmath>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "commands.hpp"
#include "cost.hpp"
#include "errors.hpp"
#include "json_reader.hpp"
#include "memory.hpp"
#include "registry.hpp"
#include "run.hpp"
#include "verify.hpp"

namespace py = pybind11;
using nlohmann::json;

namespace varia::host {
namespace {

struct FailureTag {};
py::handle failure_type;  // _varia.Failure, set when the module is made

// Where the module is: build/python/varia in the build tree, <prefix>/lib/python3/dist-packages/varia
// installed.
std::filesystem::path here() { return std::filesystem::path(boost::dll::this_line_location().string()).parent_path(); }

// The first of the candidates that exists (else the first).
std::filesystem::path first_existing(std::vector<std::filesystem::path> candidates) {
  for (auto& path : candidates)
    if (std::filesystem::exists(path)) return path.lexically_normal();
  return candidates.front().lexically_normal();
}

// The bundled plugins: build/lib/varia/plugins, or <prefix>/lib/varia/plugins installed.
std::filesystem::path bundled_plugins() {
  return first_existing({here() / ".." / ".." / "lib" / "varia" / "plugins", here() / ".." / ".." / ".." / "varia" / "plugins"});
}

Registry make_registry() { return Registry(Registry::search_path({}, bundled_plugins())); }

// A scene given as a file ("path") or as JSON text ("text"), read as the CLI reads files.
json scene_document(const std::string& kind, const std::string& value) {
  return kind == "path" ? read_json_file(value) : parse_json_text(value);
}

// The JSON pointer an InputError's message starts with ("/step: expected ..."), else "".
std::string pointer_of(const std::string& message) {
  if (message.empty() || message[0] != '/') return "";
  const auto end = message.find(": ");
  return end == std::string::npos ? message : message.substr(0, end);
}

[[noreturn]] void raise(const json& payload) {
  PyErr_SetString(failure_type.ptr(), payload.dump().c_str());
  throw py::error_already_set();
}

// Runs body with a registry, turning the host's errors into `_varia.Failure` with their kind and
// what the CLI's message carries (the pointer; the plugin file, from the record the registry
// keeps, so it outlives the objects of the body; the residual).
template <class F>
auto guarded(F&& body) -> decltype(body(std::declval<Registry&>())) {
  Registry registry = make_registry();
  try {
    return body(registry);
  } catch (const py::error_already_set&) {
    throw;
  } catch (const InputError& e) {
    raise({{"kind", "scene"}, {"pointer", pointer_of(e.what())}, {"message", e.what()}});
  } catch (const PluginFault& e) {
    const std::string file = e.origin() == nullptr ? "" : Registry::record_of(e.origin()).file.string();
    const std::string from = e.origin() == nullptr ? "" : "; from " + describe(Registry::record_of(e.origin()));
    raise({{"kind", "plugin"}, {"file", file}, {"message", std::string(e.what()) + from}});
  } catch (const NumericalFailure& e) {
    raise({{"kind", "numerical"}, {"residual", std::isfinite(e.residual()) ? json(e.residual()) : json(nullptr)},
           {"message", e.what()}});
  } catch (const std::exception& e) {
    raise({{"kind", "error"}, {"message", e.what()}});
  }
}

// Numbers as `ld`'s flags take them: comma-separated, each the shortest text that reads back to it.
std::string numbers(const std::vector<double>& values) { return fmt::format("{}", fmt::join(values, ",")); }

// A numpy array of `shape` over the numbers of `values`, which it keeps alive.
py::array owning(std::vector<double>&& values, std::vector<py::ssize_t> shape) {
  auto* kept = new std::vector<double>(std::move(values));
  const py::capsule owner(kept, [](void* p) { delete static_cast<std::vector<double>*>(p); });
  return py::array_t<double>(std::move(shape), kept->data(), owner);
}

// The rows of a run, kept as the run writes them (output.every), then handed to numpy once.
class Rows final : public TrajectoryRecorder {
 public:
  void columns(int point_size, int dim, const std::vector<std::string>& observables) override {
    point_size_ = point_size;
    dim_ = dim;
    names_ = observables;
  }
  void row(double t, const double* q, const double* p, const std::vector<double>& observables) override {
    t_.push_back(t);
    q_.insert(q_.end(), q, q + point_size_);
    p_.insert(p_.end(), p, p + dim_);
    observables_.insert(observables_.end(), observables.begin(), observables.end());
  }
  // The arrays, each owning its rows' vector (moved, not copied).
  py::dict arrays() {
    const auto rows = static_cast<py::ssize_t>(t_.size());
    py::dict d;
    d["t"] = owning(std::move(t_), {rows});
    d["q"] = owning(std::move(q_), {rows, static_cast<py::ssize_t>(point_size_)});
    d["p"] = owning(std::move(p_), {rows, static_cast<py::ssize_t>(dim_)});
    d["columns"] = names_;
    d["observables"] = owning(std::move(observables_), {rows, static_cast<py::ssize_t>(names_.size())});
    return d;
  }

 private:
  int point_size_ = 0, dim_ = 0;
  std::vector<std::string> names_;
  std::vector<double> t_, q_, p_, observables_;
};

std::string plugins() {
  return guarded([](Registry& registry) {
    std::vector<Refusal> refused;
    return plugins_json(registry.list(refused)).dump();
  });
}

void validate(const std::string& kind, const std::string& value) {
  guarded([&](Registry& registry) {
    prepare_document(scene_document(kind, value), registry);
  });
}

// The trajectory and the record; a failed step is not raised here but returned as "failure" with
// the rows so far (the Python side raises NumericalFailure carrying them).
py::dict run(const std::string& kind, const std::string& value) {
  return guarded([&](Registry& registry) {
    Prepared prepared = prepare_document(scene_document(kind, value), registry);
    Rows rows;
    json record;
    RunOptions options;
    options.quiet = true;
    options.rows = &rows;
    options.record = &record;
    json failure;
    try {
      py::gil_scoped_release release;
      run_scene(prepared.scene, prepared.assembly, registry, options);
    } catch (const RunFailure& e) {
      failure = {{"step", e.step()}, {"t", e.t()}, {"residual", std::isfinite(e.residual()) ? json(e.residual()) : json(nullptr)},
                 {"message", e.what()}};
    }
    py::dict d = rows.arrays();
    d["record"] = record.dump();
    d["failure"] = failure.is_null() ? std::string() : failure.dump();
    return d;
  });
}

std::string verify(const std::string& kind, const std::string& value, const std::vector<double>& h) {
  return guarded([&](Registry& registry) {
    Prepared prepared = prepare_document(scene_document(kind, value), registry);
    check_fit_steps(prepared.scene, h);
    py::gil_scoped_release release;
    return checks_json(verify_scene(prepared.scene, prepared.assembly, registry, h)).dump();
  });
}

std::string ld(const std::string& kind, const std::string& value, const std::vector<double>& q0,
               const std::vector<double>& q1, double h) {
  return guarded([&](Registry& registry) {
    Prepared prepared = prepare_document(scene_document(kind, value), registry);
    return discrete_lagrangian(prepared, LdOptions{numbers(q0), numbers(q1), h, true}).dump();
  });
}

// The SDK's headers, for varia.lagrangian's compiler: the source tree's (in the build tree), or
// <prefix>/include installed.
std::vector<std::string> sdk_include_dirs() {
  std::vector<std::string> dirs;
  const std::string all = VARIA_SDK_INCLUDE_DIRS;
  for (std::size_t start = 0, end; start <= all.size(); start = end + 1) {
    end = all.find(':', start);
    if (end == std::string::npos) end = all.size();
    dirs.push_back(all.substr(start, end - start));
  }
  if (std::filesystem::exists(here() / ".." / ".." / "lib" / "varia" / "plugins") && std::filesystem::exists(dirs.front()))
    return dirs;
  return {(here() / ".." / ".." / ".." / ".." / "include").lexically_normal().string()};
}

// `varia cost` on scene files, writing cost.csv, cost.json and cost.svg into `out`.
void cost(const std::vector<std::string>& files, const std::vector<double>& h, const std::string& out) {
  guarded([&](Registry&) {
    CostOptions options;
    options.out = out;
    options.h = h;
    options.quiet = true;
    command_cost(CommonOptions{{bundled_plugins().string()}}, files, options);
  });
}

}  // namespace
}  // namespace varia::host

PYBIND11_MODULE(_varia, m) {
  m.doc() = "varia's host, for the varia package (docs/python.md)";
  varia::host::keep_freed_memory();
  static py::exception<varia::host::FailureTag> failure(m, "Failure");
  varia::host::failure_type = failure;
  m.def("plugins", &varia::host::plugins);
  m.def("validate", &varia::host::validate);
  m.def("run", &varia::host::run);
  m.def("verify", &varia::host::verify);
  m.def("ld", &varia::host::ld);
  m.def("cost", &varia::host::cost);
  m.def("sdk_include_dirs", &varia::host::sdk_include_dirs);
}
