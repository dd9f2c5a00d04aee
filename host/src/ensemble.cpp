#include "ensemble.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <cmath>
#include <cstdlib>
#include <exception>
#include <mutex>
#include <optional>
#include <random>
#include <thread>

#include "ensemble_file.hpp"
#include "ensemble_members.hpp"
#include "ensemble_mpi.hpp"
#include "errors.hpp"
#include "interrupt.hpp"
#include "json_reader.hpp"
#include "numbers.hpp"
#include "output.hpp"
#include "plot.hpp"
#include "progress.hpp"
#include "registry.hpp"
#include "run.hpp"
#include "scene.hpp"

namespace varia::host {

using json = nlohmann::json;

namespace {

// The most members an ensemble may have (the product of the --vary specs' sizes): its file holds
// a row of every dataset for each, allocated when it is created.
constexpr double kMaxMembers = 1e7;

[[noreturn]] void refuse_vary(const std::string& text, const std::string& why) {
  throw InputError(fmt::format("--vary: expected POINTER=linspace:A:B:N, POINTER=list:A,B,... or "
                               "POINTER=uniform:A:B:N:SEED ({}); found '{}'",
                               why, printable(text)));
}

double finite_number(const std::string& word, const std::string& text) {
  const std::optional<double> x = host::finite_number(word);
  if (!x) refuse_vary(text, "'" + word + "' is not a finite number");
  return *x;
}

long count_of(const std::string& word, const std::string& text) {
  const double n = finite_number(word, text);
  if (n < 1 || n != std::floor(n) || n > kMaxMembers) refuse_vary(text, "N is a whole number from 1 to 10^7");
  return static_cast<long>(n);
}

}  // namespace

VarySpec parse_vary(const std::string& text) {
  const auto equals = text.find('=');
  if (equals == std::string::npos || text.empty() || text[0] != '/') refuse_vary(text, "a JSON pointer, then '='");
  VarySpec spec{text, text.substr(0, equals), {}};
  const auto parts = split(text.substr(equals + 1), ':');
  const std::string& kind = parts[0];
  if (kind == "list" && parts.size() == 2) {
    const std::optional<std::vector<double>> values = comma_separated_numbers(parts[1]);
    if (!values) refuse_vary(text, "'" + parts[1] + "' is not a list of comma-separated finite numbers");
    spec.values = *values;
  } else if (kind == "linspace" && parts.size() == 4) {
    const double a = finite_number(parts[1], text), b = finite_number(parts[2], text);
    const long n = count_of(parts[3], text);
    for (long k = 0; k < n; ++k) spec.values.push_back(n == 1 ? a : a + (b - a) * static_cast<double>(k) / (n - 1));
  } else if (kind == "uniform" && parts.size() == 5) {
    const double a = finite_number(parts[1], text), b = finite_number(parts[2], text);
    const long n = count_of(parts[3], text);
    const double seed = finite_number(parts[4], text);
    if (seed < 0 || seed != std::floor(seed) || seed > 1.8e19) refuse_vary(text, "SEED is a whole number >= 0");
    std::mt19937_64 generator(static_cast<std::uint64_t>(seed));
    for (long k = 0; k < n; ++k) spec.values.push_back(a + (b - a) * std::ldexp(static_cast<double>(generator() >> 11), -53));
  } else {
    refuse_vary(text, "one of the three forms");
  }
  return spec;
}

namespace {

// The run record's numbers the scene's observables give, in the file's order.
std::vector<std::string> record_numbers(const Observe& o) {
  std::vector<std::string> keys;
  const std::pair<bool, const char*> all[] = {
      {o.energy, "energy_error_max"},       {o.momentum, "momentum_error_max"},
      {o.orthogonality, "orthogonality_error_max"}, {o.constraint, "constraint_error_max"},
      {o.constraint_velocity, "constraint_velocity_error_max"}, {o.megno, "megno_final"},
      {o.lyapunov, "lyapunov_final"}};
  for (const auto& [asked, key] : all)
    if (asked) keys.emplace_back(key);
  return keys;
}

json member_document(const Plan& plan, long member) {
  json document = plan.document;
  std::vector<std::string> settings;
  for (int v = 0; v < plan.layout.varies; ++v)
    settings.push_back(plan.varies[v].pointer + "=" + json(plan.parameters[member * plan.layout.varies + v]).dump());
  apply_settings(document, settings);
  return document;
}

}  // namespace

MemberResult run_member(const Plan& plan, long member, Registry& registry, std::mutex& prepare, std::string& message) {
  MemberResult r;
  r.numbers.assign(plan.layout.numbers.size(), std::nan(""));
  json record;
  try {
    std::optional<Prepared> prepared;
    {
      const std::lock_guard<std::mutex> lock(prepare);
      prepared.emplace(prepare_document(member_document(plan, member), registry));
    }
    if (prepared->assembly.map->point_size() != plan.layout.point_size || prepared->assembly.map->dim() != plan.layout.dim)
      throw InputError(fmt::format("the member's state has {} + {} numbers, the first member's {} + {}: an ensemble's "
                                   "members share their sizes",
                                   prepared->assembly.map->point_size(), prepared->assembly.map->dim(),
                                   plan.layout.point_size, plan.layout.dim));
    RunOptions options;
    options.quiet = true;
    options.warnings = false;
    options.record = &record;
    run_scene(prepared->scene, prepared->assembly, registry, options);
    r.status = 0;
  } catch (const Interrupted&) {
    throw;
  } catch (...) {
    r.status = exit_code_of(std::current_exception(), message);
  }
  if (record.contains("final")) {
    r.t = record["final"]["t"].get<double>();
    r.q = record["final"]["q"].get<std::vector<double>>();
    r.p = record["final"]["p"].get<std::vector<double>>();
  } else {
    r.t = std::nan("");
  }
  for (std::size_t k = 0; k < r.numbers.size(); ++k)
    if (record.contains(plan.layout.numbers[k]) && record[plan.layout.numbers[k]].is_number())
      r.numbers[k] = record[plan.layout.numbers[k]].get<double>();
  return r;
}

namespace {

Plan make_plan(const std::string& scene_file, const CommonOptions& common, const EnsembleOptions& options,
               Registry& registry) {
  Plan plan;
  try {
    plan.document = read_json_file(scene_file);
    apply_settings(plan.document, common.settings);
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}", scene_file, e.what()));
  }
  plan.scene_text = plan.document.dump();
  double members = 1;
  json specs = json::array();
  for (const auto& text : options.vary) {
    plan.varies.push_back(parse_vary(text));
    members *= static_cast<double>(plan.varies.back().values.size());
    specs.push_back(text);
  }
  if (members > kMaxMembers)
    throw InputError(fmt::format("--vary: expected at most {:g} members in all; the specs' product has {:g}",
                                 kMaxMembers, members));
  plan.vary_text = specs.dump();
  plan.layout.members = static_cast<long>(members);
  plan.layout.varies = static_cast<int>(plan.varies.size());
  for (long m = 0; m < plan.layout.members; ++m) {
    long rest = m;
    std::vector<double> row(plan.varies.size());
    for (int v = plan.layout.varies - 1; v >= 0; --v) {
      const auto size = static_cast<long>(plan.varies[v].values.size());
      row[v] = plan.varies[v].values[rest % size];
      rest /= size;
    }
    plan.parameters.insert(plan.parameters.end(), row.begin(), row.end());
  }
  // The first member's scene gives the sizes and the observables; refused, it ends the command.
  try {
    const Prepared first = prepare_document(member_document(plan, 0), registry);
    plan.layout.point_size = first.assembly.map->point_size();
    plan.layout.dim = first.assembly.map->dim();
    plan.layout.numbers = record_numbers(first.scene.observe);
  } catch (const InputError& e) {
    throw InputError(fmt::format("{} (the first member, {}): {}", scene_file, plan.vary_text, e.what()));
  }
  return plan;
}

}  // namespace

void say_failure(const Plan& plan, long member, const MemberResult& r, const std::string& message) {
  if (r.status == 0 || message.empty()) return;
  std::vector<std::string> values;
  for (int v = 0; v < plan.layout.varies; ++v)
    values.push_back(fmt::format("{}={}", printable(plan.varies[v].pointer), plan.parameters[member * plan.layout.varies + v]));
  fmt::print(stderr, "varia: ensemble: member {} ({}) exits {}: {}\n", member, fmt::join(values, ", "), r.status,
             printable(message));
}

namespace {

// The members on `threads` threads of this process.
void run_on_threads(Dispatcher& dispatcher, const CommonOptions& common, int threads) {
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back([&] { dispatcher.work(common); });
  dispatcher.work(common);
  for (auto& thread : pool) thread.join();
  dispatcher.rethrow();
}

// --plot: MEGNO over the grid of the two --vary (clipped to [0, 8]: 2 is quasi-periodic order,
// far above it chaos).
void check_plot(const Plan& plan, const EnsembleOptions& options) {
  if (!options.plot) return;
  const bool megno = std::find(plan.layout.numbers.begin(), plan.layout.numbers.end(), "megno_final") !=
                     plan.layout.numbers.end();
  if (plan.layout.varies != 2 || !megno)
    throw InputError("--plot: expected two --vary and a scene observing \"megno\": the plot is the stability map, "
                     "MEGNO over the grid of the two varied values");
}

void plot_map(const Plan& plan, const EnsembleFile& file, const std::filesystem::path& to) {
  GridMap map{"MEGNO (clipped to [0, 8]; blank: a member that failed or was not run)",
              plan.varies[0].pointer, plan.varies[1].pointer, "MEGNO", plan.varies[0].values, plan.varies[1].values,
              file.numbers("megno_final"), 0.0, 8.0};
  const auto statuses = file.statuses();
  for (std::size_t m = 0; m < map.z.size(); ++m)
    if (statuses[m] != 0) map.z[m] = std::nan("");
  write_map_svg(to, map);
}

int finish(const Plan& plan, EnsembleFile& file, const Dispatcher& dispatcher, const EnsembleOptions& options,
           double seconds) {
  if (options.plot) plot_map(plan, file, *options.plot);
  file.close();
  long run = 0, failed = 0;
  for (int s : file.statuses()) run += s >= 0, failed += s > 0;
  if (!options.quiet)
    fmt::print(results(), "ensemble: {} members, {} run now, {} held in all, {} failed; {:.2f} s; {}\n",
               plan.layout.members, dispatcher.done(), run, failed, seconds, printable(options.out.string()));
  stop_if_interrupted(fmt::format("after {} of {} members; {} holds them, and --resume runs the rest", run,
                                  plan.layout.members, printable(options.out.string())));
  return 0;
}

}  // namespace

int command_ensemble(const CommonOptions& common, const std::string& scene_file, const EnsembleOptions& options) {
  if (options.out.extension() != ".h5")
    throw InputError(fmt::format("--out: expected a file name ending in .h5; found '{}'", printable(options.out.string())));
  if (options.threads < 1 || options.threads > 1024)
    throw InputError(fmt::format("--threads: expected a number from 1 to 1024; found {}", options.threads));
  const bool distributed = mpi_processes() > 1;
  std::optional<MpiSession> mpi;
  if (distributed) mpi.emplace();
  return with_registry(common, [&](Registry& registry) {
    const auto start = std::chrono::steady_clock::now();
    const Plan plan = make_plan(scene_file, common, options, registry);
    check_plot(plan, options);
    if (distributed && mpi->rank() != 0) {
      worker(plan, common, options.threads);
      return 0;
    }
    EnsembleFile file(options.out, plan.scene_text, plan.vary_text, plan.layout, plan.parameters, options.resume);
    std::vector<long> todo;
    for (long m = 0; m < plan.layout.members; ++m)
      if (file.statuses()[static_cast<std::size_t>(m)] < 0) todo.push_back(m);
    ProgressLine progress("member", static_cast<long>(todo.size()), options.quiet);
    Dispatcher dispatcher(plan, todo, file, progress);
    if (distributed) master(dispatcher, common, mpi->size() - 1, options.threads);
    else run_on_threads(dispatcher, common, options.threads);
    return finish(plan, file, dispatcher, options,
                  std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  });
}

}  // namespace varia::host
