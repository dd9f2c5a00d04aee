#include "cost.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <deque>
#include <map>
#include <stdexcept>

#include "assemble.hpp"
#include "errors.hpp"
#include "interrupt.hpp"
#include "observer.hpp"
#include "output.hpp"
#include "plot.hpp"
#include "registry.hpp"
#include "scene.hpp"
#include "varia/core/trajectory.hpp"
#include "varia/core/verification.hpp"

namespace varia::host {

namespace {

using Clock = std::chrono::steady_clock;
using json = nlohmann::ordered_json;

// The energy is sampled at most this often per run (every state of shorter runs); the stepping
// between samples is what `seconds` times, so sampling costs no measured time.
constexpr long kEnergySamples = 1000;
// Runs shorter than this are repeated (without sampling) and the fastest repeat is kept: a
// single short run is dominated by timer resolution and cold caches.
constexpr double kShortRun = 0.05;
constexpr int kMaxRepeats = 20;
// The default sweep: the scene's step times 2^2, 2^1, ..., 2^-4 (7 step sizes, 6 halvings).
constexpr int kSweepAbove = 2, kSweepBelow = 4;

// One run of the sweep: a row of cost.csv.
struct Row {
  double h = 0.0;
  long steps = 0;
  double error = 0.0, energy_error = 0.0, seconds = 0.0;
  long newton_iterations = 0, evaluations = 0;
};

// What a run is measured against: the exact solution or a reference run at the final time.
struct Truth {
  Eigen::VectorXd q, p;
  std::string source;        // "exact solution" or the reference run's description
  double uncertainty = 0.0;  // the change of the reference on halving its step (0: exact)
};

struct Method {
  std::string name, file;
  Scene scene;
  Assembly assembly;
  int predicted_order = 0;
  std::vector<Row> rows;
  const Truth* truth = nullptr;
  OrderFit fit;
};

// ---- one run --------------------------------------------------------------------------------

long evaluation_count(const EvaluationCounters& c) { return c.lagrangian + c.gradient + c.hessian; }

double distance(const TimedRun& f, const Truth& truth) {
  return std::max((f.q - truth.q).lpNorm<Eigen::Infinity>(), (f.p - truth.p).lpNorm<Eigen::Infinity>());
}

// One row: a sampled, timed run for the error and the counts, then, for a short run, untimed
// repeats keeping the fastest.
Row measure(Method& m, double h, long steps) {
  Assembly& a = m.assembly;
  const long evaluations = evaluation_count(a.map->evaluations());
  const long iterations = a.map->solver_statistics().iterations;
  Observer observer(Observe::energy_only(), *a.manifold, *a.lagrangian, a.v0, m.scene.solver);
  const TimedRun f = run_timed(a, h, steps, &observer);
  Row row{h, steps, distance(f, *m.truth), observer.energy_error(), f.seconds,
          a.map->solver_statistics().iterations - iterations, evaluation_count(a.map->evaluations()) - evaluations};
  double spent = f.seconds;
  for (int r = 0; r < kMaxRepeats && row.seconds < kShortRun && spent < 4 * kShortRun; ++r) {
    const double seconds = run_timed(a, h, steps, nullptr).seconds;
    row.seconds = std::min(row.seconds, seconds);
    spent += seconds;
  }
  return row;
}

// ---- the truth: exact solution or a converged reference run -----------------------------------

// The length of the scene's run (from initial.t to t_end).
double final_time(const Scene& scene) { return static_cast<double>(scene.steps) * scene.step; }

long steps_for(double t_end, double h) { return std::max(1L, std::lround(t_end / h)); }

Truth exact_truth(Assembly& a, double t_end) {
  Truth truth{Eigen::VectorXd(a.q0.size()), Eigen::VectorXd(a.p0.size()), "exact solution", 0.0};
  Eigen::VectorXd v(a.v0.size());
  check(*a.lagrangian, a.lagrangian->exact_solution(a.q0.data(), a.v0.data(), t_end, truth.q.data(), v.data()),
        "exact solution");
  LagrangianEvaluator(*a.lagrangian).legendre(truth.q.data(), v.data(), truth.p.data());
  return truth;
}

// Runs `a` at h, h/2, h/4, ... until two successive runs agree to `target` (at most 4 halvings):
// the reference is the last run, its uncertainty the last change.
Truth converge(const Assembly& a, double t_end, double h, double target, const std::string& what) {
  TimedRun last = run_timed(a, t_end / steps_for(t_end, h), steps_for(t_end, h), nullptr);
  double change = 0.0;
  for (int halving = 1; halving <= 4; ++halving) {
    h /= 2;
    TimedRun next = run_timed(a, t_end / steps_for(t_end, h), steps_for(t_end, h), nullptr);
    change = std::max((next.q - last.q).lpNorm<Eigen::Infinity>(), (next.p - last.p).lpNorm<Eigen::Infinity>());
    last = std::move(next);
    if (change <= target) break;
  }
  return Truth{last.q, last.p, fmt::format("{} at h = {:.6g} (changes by {:.2e} on halving h)", what, h, change),
               change};
}

// Methods share a truth when they integrate the same system from the same state to the same time.
std::string system_key(const Scene& s) {
  std::string key = fmt::format("{}|{}|{}|{}|{}|{}", s.manifold.type, s.manifold.parameters.dump(), s.lagrangian.type,
                                s.lagrangian.parameters.dump(), s.t0, final_time(s));
  for (const PluginSpec& force : s.forces) key += "|" + force.type + force.parameters.dump();
  for (const auto* values : {&s.q, s.p ? &*s.p : &*s.v}) key += fmt::format("|{}", fmt::join(*values, ","));
  return key + (s.p ? "|p" : "|v");
}

// A converged reference run of the method's system: the Galerkin reference where the manifold
// allows it, else the method of this system with the highest predicted order, in both cases
// at steps below the smallest of the sweep.
Truth reference_truth(const Method& m, const std::deque<Method>& methods, Registry& registry, double h_min) {
  const double t_end = final_time(m.scene), target = 1e-12 * std::max(1.0, m.assembly.q0.lpNorm<Eigen::Infinity>());
  try {
    // Galerkin of degree 4 with 4 Gauss-Legendre points: order 8, far above the orders it checks.
    Assembly reference = assemble(galerkin_reference(m.scene, m.assembly, 4, 4), registry);
    return converge(reference, t_end, h_min / 2, target,
                    "reference run: galerkin degree 4, gauss-legendre 4 points (order 8)");
  } catch (const std::invalid_argument&) {
  } catch (const InputError&) {
  }
  const Method* best = &m;
  for (const Method& other : methods)
    if (other.predicted_order > best->predicted_order && system_key(other.scene) == system_key(m.scene))
      best = &other;
  return converge(best->assembly, t_end, h_min / 4, target,
                  fmt::format("reference run: {} (order {})", best->name, best->predicted_order));
}

// ---- methods ----------------------------------------------------------------------------------

// The scene's optional top-level "name", else the file's stem.
std::string method_name(const std::string& file) {
  const auto document = read_json_file(file);
  if (document.contains("name") && document["name"].is_string()) return document["name"].get<std::string>();
  return std::filesystem::path(file).stem().string();
}

void load_method(const std::string& file, const CommonOptions& common, Registry& registry, std::deque<Method>& methods) {
  Method& m = methods.emplace_back();
  m.file = file;
  try {
    m.name = method_name(file);
    m.scene = load_scene(file, registry, common.settings);
    m.scene.observe = Observe::energy_only();  // the energy error is always measured
    m.assembly = assemble(m.scene, registry);
    // The order the theorems give for the parts that assemble() recorded (verification.hpp).
    m.predicted_order = m.scene.construction->predict(m.scene, m.assembly).global_order.value_or(0);
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}", file, e.what()));
  }
}

std::vector<double> step_sizes(const Scene& scene, const CostOptions& options) {
  std::vector<double> h = options.h;
  if (h.empty())
    for (int k = kSweepAbove; k >= -kSweepBelow; --k) h.push_back(std::ldexp(scene.step, k));
  std::sort(h.begin(), h.end(), std::greater<>());
  return h;
}

// A progress line on stderr when it is a terminal (spec: "Progress and diagnostics"); the scene's
// name in it is shown printable.
void progress(const CostOptions& options, const std::string& text) {
  if (options.quiet || !::isatty(STDERR_FILENO)) return;
  std::fprintf(stderr, "\r\033[K%s", printable(text).c_str());
  std::fflush(stderr);
}

void sweep(Method& m, const CostOptions& options, int index, int count) {
  const double t_end = final_time(m.scene);
  for (double h : step_sizes(m.scene, options)) {
    stop_if_interrupted(fmt::format("during the sweep of {}", m.name));
    const long steps = steps_for(t_end, h);
    progress(options, fmt::format("varia: cost: method {} of {} ({}), h = {:.4g}, {} steps", index + 1, count,
                                  m.name, t_end / steps, steps));
    try {
      m.rows.push_back(measure(m, t_end / steps, steps));
    } catch (const NumericalFailure& e) {
      progress(options, "");
      fmt::print(stderr, "varia: cost: {}: h = {:.4g} skipped: {}\n", printable(m.name), t_end / steps,
                 printable(e.what()));
    }
  }
  if (m.rows.empty()) throw NumericalFailure(fmt::format("{}: no step size ran to the end", m.file), std::nan(""));
}

void fit(Method& m) {
  std::vector<double> h, error;
  for (const Row& row : m.rows) h.push_back(row.h), error.push_back(row.error);
  const double scale = std::max(1.0, m.truth->q.lpNorm<Eigen::Infinity>());
  m.fit = fit_order(h, error, std::max(1e-12 * scale, 10 * m.truth->uncertainty));
}

// ---- outputs ----------------------------------------------------------------------------------

// --out names a directory (made if missing) whose cost.csv, cost.json and cost.svg are none of the
// scene files.
void check_cost_outputs(const std::vector<std::string>& scene_files, const std::filesystem::path& out) {
  std::error_code ec;
  std::filesystem::create_directories(out, ec);
  if (!std::filesystem::is_directory(out))
    throw InputError(fmt::format("--out {}: expected a directory (or a path where one can be made){}", out.string(),
                                 ec ? ": " + ec.message() : ""));
  std::vector<NamedFile> inputs;
  for (const auto& file : scene_files) inputs.push_back({"scene", file});
  check_distinct(inputs, {{"--out", out / "cost.csv"}, {"--out", out / "cost.json"}, {"--out", out / "cost.svg"}});
}

// Every step size of the sweep gives a number of steps the scene reader would accept (at least
// one step of at most t_end, at most kMaxFlagSteps).
void check_step_sizes(const Method& m, const std::vector<double>& flags) {
  const double t_end = final_time(m.scene);
  for (double h : flags) check_step_flag(h, t_end, fmt::format("t_end = {} of {}", t_end, m.file));
}

std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

void write_csv(const std::filesystem::path& file, const std::deque<Method>& methods) {
  std::string text = "method,h,steps,error,energy_error,seconds,newton_iterations,evaluations\n";
  for (const Method& m : methods)
    for (const Row& r : m.rows)
      text += fmt::format("{},{},{},{:.6e},{:.6e},{:.6e},{},{}\n", csv_field(m.name), r.h, r.steps, r.error,
                          r.energy_error, r.seconds, r.newton_iterations, r.evaluations);
  write_output(file, text, "--out");
}

// The method's line of cost.json: its prediction and fit, and its rows (cost.csv's, at full precision).
json method_record(const Method& m) {
  json rows = json::array();
  for (const Row& r : m.rows)
    rows.push_back({{"h", r.h}, {"steps", r.steps}, {"error", r.error}, {"energy_error", r.energy_error},
                    {"seconds", r.seconds}, {"newton_iterations", r.newton_iterations}, {"evaluations", r.evaluations}});
  return {{"method", m.name},
          {"scene", m.file},
          {"predicted_order", m.predicted_order},
          {"fitted_slope", m.fit.fitted() ? json(m.fit.slope) : json(nullptr)},
          {"points_fitted", m.fit.used},
          {"points_dropped", m.fit.dropped},
          {"reference", m.truth->source},
          {"rows", rows}};
}

// The predicted slope, drawn through the method's smallest-h point that the fit kept.
Series slope_line(const Method& m) {
  Series line{fmt::format("{}: slope {}", m.name, m.predicted_order), {}, {}, true};
  const double floor = 10 * m.truth->uncertainty;
  const auto anchor = std::find_if(m.rows.rbegin(), m.rows.rend(), [&](const Row& r) { return r.error > floor; });
  if (anchor == m.rows.rend() || m.predicted_order <= 0) return line;
  for (const Row* r : {&m.rows.front(), &m.rows.back()}) {
    line.x.push_back(r->h);
    line.y.push_back(anchor->error * std::pow(r->h / anchor->h, m.predicted_order));
  }
  return line;
}

void write_plot(const std::filesystem::path& file, const std::deque<Method>& methods) {
  Panel work{"work-precision", "seconds (stepping loop)", "global error at the final time", true, true, {}};
  Panel order{"error against step size (dashed: predicted order)", "step size h", "global error at the final time",
              true, true, {}};
  Panel energy{"energy error against cost", "seconds (stepping loop)", "max |E - E0| over the run", true, true, {}};
  for (const Method& m : methods) {
    Series by_time{m.name, {}, {}, false}, by_h{m.name, {}, {}, false}, energy_by_time{m.name, {}, {}, false};
    for (const Row& r : m.rows) {
      by_time.x.push_back(r.seconds);
      by_time.y.push_back(r.error);
      by_h.x.push_back(r.h);
      by_h.y.push_back(r.error);
      energy_by_time.x.push_back(r.seconds);
      energy_by_time.y.push_back(r.energy_error);
    }
    work.series.push_back(std::move(by_time));
    order.series.push_back(std::move(by_h));
    energy.series.push_back(std::move(energy_by_time));
  }
  for (const Method& m : methods) order.series.push_back(slope_line(m));
  write_svg(file, {work, order, energy});
}

// The method's rows; its name, file and reference (text from the scenes) shown printable.
void print_table(const Method& m) {
  fmt::print(results(), "{} ({}): predicted order {}, fitted slope {}\n  error measured against the {}\n",
             printable(m.name), printable(m.file), m.predicted_order,
             m.fit.fitted() ? fmt::format("{:.2f} ({} points)", m.fit.slope, m.fit.used) : "-",
             printable(m.truth->source));
  fmt::print(results(), "  {:>10} {:>8} {:>11} {:>11} {:>10} {:>11} {:>11}\n", "h", "steps", "error", "energy err", "seconds",
             "Newton/step", "evals/step");
  for (const Row& r : m.rows)
    fmt::print(results(), "  {:>10.4g} {:>8} {:>11.3e} {:>11.3e} {:>10.3e} {:>11.2f} {:>11.2f}\n", r.h, r.steps, r.error,
               r.energy_error, r.seconds, static_cast<double>(r.newton_iterations) / r.steps,
               static_cast<double>(r.evaluations) / r.steps);
  for (const auto& why : m.fit.dropped) fmt::print(results(), "  not fitted: {}\n", why);
  if (!m.fit.extrapolated.empty()) fmt::print(results(), "  extrapolated: {}\n", m.fit.extrapolated);
}

}  // namespace

TimedRun run_timed(const Assembly& a, double h, long steps, Observer* observer) {
  Trajectory trajectory(*a.map, a.q0, a.p0, a.t0, h);
  double seconds = 0.0;
  const long stride = observer ? std::max(1L, steps / kEnergySamples) : steps;
  if (observer) observer->observe(a.q0.data(), a.p0.data());
  while (trajectory.steps() < steps) {
    const auto start = Clock::now();
    trajectory.advance(std::min(stride, steps - trajectory.steps()));
    seconds += std::chrono::duration<double>(Clock::now() - start).count();
    if (observer) observer->observe(trajectory.q().data(), trajectory.p().data());
  }
  return TimedRun{trajectory.q(), trajectory.p(), seconds};
}

int command_cost(const CommonOptions& common, const std::vector<std::string>& scene_files,
                 const CostOptions& options) {
  check_cost_outputs(scene_files, options.out);
  return with_registry(common, [&](Registry& registry) {
    std::deque<Method> methods;  // a deque: an Assembly stays where it was built
    for (const auto& file : scene_files) load_method(file, common, registry, methods);
    for (const Method& m : methods) check_step_sizes(m, options.h);

    std::map<std::string, Truth> truths;
    for (Method& m : methods) {
      const double t_end = final_time(m.scene), h_min = t_end / steps_for(t_end, step_sizes(m.scene, options).back());
      auto [it, fresh] = truths.try_emplace(system_key(m.scene));
      if (fresh) {
        progress(options, fmt::format("varia: cost: the truth for {}", m.name));
        it->second = has_exact_solution(m.assembly) ? exact_truth(m.assembly, final_time(m.scene))
                                                    : reference_truth(m, methods, registry, h_min);
      }
      m.truth = &it->second;
    }
    for (std::size_t i = 0; i < methods.size(); ++i)
      sweep(methods[i], options, static_cast<int>(i), static_cast<int>(methods.size()));
    progress(options, "");

    json record{{"methods", json::array()}};
    for (Method& m : methods) {
      fit(m);
      record["methods"].push_back(method_record(m));
      if (!options.quiet) print_table(m);
    }
    write_csv(options.out / "cost.csv", methods);
    write_json_file(options.out / "cost.json", record, "--out");
    write_plot(options.out / "cost.svg", methods);
    if (!options.quiet)
      fmt::print(results(), "wrote {}, cost.svg, cost.json\n", printable((options.out / "cost.csv").string()));
    return 0;
  });
}

}  // namespace varia::host
