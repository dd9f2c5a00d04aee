#include "run.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "interrupt.hpp"
#include "observer.hpp"
#include "hdf5_output.hpp"
#include "output.hpp"
#include "plot.hpp"
#include "progress.hpp"
#include "registry.hpp"
#include "varia/core/trajectory.hpp"

namespace varia::host {

using json = nlohmann::ordered_json;

namespace {

using Clock = std::chrono::steady_clock;

// The longest stretch of unobserved steps taken without a look at the interruption flag and the
// progress line: a fraction of a second for a step of a millisecond.
constexpr long kStretch = 256;

std::vector<std::string> csv_columns(int point_size, int dim, const Observer& observer) {
  std::vector<std::string> columns{"t"};
  for (int i = 0; i < point_size; ++i) columns.push_back(fmt::format("q{}", i));
  for (int i = 0; i < dim; ++i) columns.push_back(fmt::format("p{}", i));
  for (auto& name : observer.columns()) columns.push_back(std::move(name));
  return columns;
}

struct Failure {
  long step;  // the step that failed: from step - 1 to step
  double t;   // the time it started from
  double residual;
  std::string message;
  const void* origin = nullptr;  // the plugin object whose output was not finite, if one was
};


// Spec "Outputs": the run record's keys.
json run_record(const Scene& scene, Assembly& a, const Observer& observer, const Trajectory& state,
                const RunOutcome& outcome, const Registry& registry) {
  Eigen::VectorXd written;
  const Eigen::VectorXd& p = written_momentum(a, state.q(), state.p(), written);
  const auto& statistics = a.map->solver_statistics();
  const auto& evaluations = a.map->evaluations();
  json record{
      {"steps", state.steps()},
      {"wall_seconds", outcome.wall_seconds},
      {"newton_iterations", {{"mean", statistics.mean()}, {"max", statistics.max_iterations}}},
      {"evaluations",
       {{"lagrangian", evaluations.lagrangian},
        {"gradient", evaluations.gradient},
        {"hessian", evaluations.hessian},
        {"force", evaluations.force}}},
      {"final", {{"t", state.t()}, {"q", as_vector(state.q())}, {"p", as_vector(p)}}},
  };
  if (scene.observe.energy) record["energy_error_max"] = observer.energy_error();
  if (scene.observe.momentum) record["momentum_error_max"] = observer.momentum_error();
  if (scene.observe.orthogonality) record["orthogonality_error_max"] = observer.orthogonality_error();
  if (scene.observe.constraint) record["constraint_error_max"] = observer.constraint_error();
  if (scene.observe.constraint_velocity) record["constraint_velocity_error_max"] = observer.constraint_velocity_error();
  if (scene.observe.megno) record["megno_final"] = state.chaos().megno();
  if (scene.observe.lyapunov) record["lyapunov_final"] = state.chaos().lyapunov();
  record["plugins_loaded"] = registry.loaded();
  return record;
}

void print_human_summary(std::FILE* to, const Scene& scene, const Assembly& a, const Observer& observer,
                         const Trajectory& state, const RunOutcome& outcome) {
  const auto& statistics = a.map->solver_statistics();
  const std::string method = scene.construction->describe(scene);
  fmt::print(to, "system            {} on {}\n", scene.lagrangian.type, manifold_name(scene.manifold));
  fmt::print(to, "method            {}, h = {}\n", method, scene.step);
  fmt::print(to, "steps             {}\n", state.steps());
  fmt::print(to, "final time        {:.10g}\n", state.t());
  if (scene.observe.energy) fmt::print(to, "energy error max  {:.3e}\n", observer.energy_error());
  if (scene.observe.momentum) fmt::print(to, "momentum error    {:.3e}\n", observer.momentum_error());
  if (scene.observe.orthogonality) fmt::print(to, "orthogonality     {:.3e}\n", observer.orthogonality_error());
  if (scene.observe.constraint) fmt::print(to, "constraint max    {:.3e}\n", observer.constraint_error());
  if (scene.observe.constraint_velocity)
    fmt::print(to, "constraint velocity max {:.3e}\n", observer.constraint_velocity_error());
  if (scene.observe.megno) fmt::print(to, "MEGNO             {:.4f}\n", state.chaos().megno());
  if (scene.observe.lyapunov) fmt::print(to, "Lyapunov exponent {:.4e}\n", state.chaos().lyapunov());
  fmt::print(to, "Newton iterations mean {:.2f}, max {}\n", statistics.mean(), statistics.max_iterations);
  fmt::print(to, "wall time         {:.4f} s\n", outcome.wall_seconds);
}

// `run --plot` draws at most this many stretches of rows per curve, two points each.
constexpr long kPlotStretches = 1000;

// One curve of `run --plot`, bounded whatever the number of rows: the rows come in stretches of
// `per_stretch` consecutive ones, and each stretch is drawn as its smallest and its largest value,
// in the order they came, so that the line reaches every extreme of the run.
class DecimatedCurve {
 public:
  explicit DecimatedCurve(long per_stretch) : per_stretch_(per_stretch) {}
  void add(double t, double y) {
    if (count_ == 0 || y < low_.y) low_ = {t, y};
    if (count_ == 0 || y > high_.y) high_ = {t, y};
    if (++count_ == per_stretch_) end_stretch();
  }
  Series series(std::string title) {
    end_stretch();
    return Series{std::move(title), t_, y_, false};
  }

 private:
  struct Point {
    double t = 0.0, y = 0.0;
  };
  void end_stretch() {
    if (count_ == 0) return;
    const bool low_first = low_.t <= high_.t;
    draw(low_first ? low_ : high_);
    if (low_.t != high_.t) draw(low_first ? high_ : low_);
    count_ = 0;
  }
  void draw(const Point& point) {
    t_.push_back(point.t);
    y_.push_back(point.y);
  }
  long per_stretch_, count_ = 0;
  Point low_, high_;
  std::vector<double> t_, y_;
};

// `run --plot`'s phase portrait keeps at most this many rows (every k-th).
constexpr long kPhasePoints = 4000;

// The written rows as `run --plot` draws them, in three panels: the configuration against t, the
// phase portrait, and |E - E0| on a log scale when the energy is observed (else p against t).
// The configuration is q's first three numbers on a vector space; on a Lie group, whose point is
// matrix entries, the natural-chart coordinates xi = log(q(0)^{-1} q) of the start. The phase
// portrait draws p_i against coordinate i (up to three pairs) at every k-th row. Whatever the
// number of rows, every curve is bounded (DecimatedCurve, kPhasePoints).
class PlotRecorder {
 public:
  PlotRecorder(Manifold& manifold, bool energy, long rows)
      : manifold_(manifold),
        energy_(energy),
        per_stretch_((rows + kPlotStretches - 1) / kPlotStretches),
        phase_every_((rows + kPhasePoints - 1) / kPhasePoints),
        coordinates_(manifold.is_vector_space() ? manifold.point_size() : manifold.dim()) {}

  void record(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& p, const std::vector<double>& values) {
    if (configuration_.empty()) start(q, values);
    if (manifold_.is_vector_space()) coordinates_ = q;
    else check(manifold_, manifold_.local(start_.data(), q.data(), coordinates_.data()), "local");
    for (std::size_t i = 0; i < configuration_.size(); ++i) configuration_[i].add(t, coordinates_[index(i)]);
    for (std::size_t i = 0; i < right_.size(); ++i)
      right_[i].add(t, energy_ ? std::abs(values[0] - initial_energy_) : p[index(i)]);
    if (rows_++ % phase_every_ == 0)
      for (std::size_t i = 0; i < phase_.size(); ++i) {
        phase_[i].x.push_back(coordinates_[index(i)]);
        phase_[i].y.push_back(p[index(i)]);
      }
  }

  void write(const std::filesystem::path& file) {
    const char* q = manifold_.is_vector_space() ? "q" : "xi";
    std::vector<Series> configuration, right;
    for (std::size_t i = 0; i < configuration_.size(); ++i)
      configuration.push_back(configuration_[i].series(fmt::format("{}{}", q, i)));
    for (std::size_t i = 0; i < right_.size(); ++i)
      right.push_back(right_[i].series(energy_ ? "|E - E0|" : fmt::format("p{}", i)));
    write_svg(file, {Panel{"configuration", "t", manifold_.is_vector_space() ? "q" : "xi = log(q(0)^-1 q)", false,
                           false, configuration},
                     Panel{"phase portrait", manifold_.is_vector_space() ? "q_i" : "xi_i", "p_i", false, false, phase_},
                     Panel{energy_ ? "energy error" : "momentum", "t", energy_ ? "|E(t) - E(0)|" : "p", false, energy_,
                           right}});
  }

 private:
  static Eigen::Index index(std::size_t i) { return static_cast<Eigen::Index>(i); }
  void start(const Eigen::VectorXd& q, const std::vector<double>& values) {
    start_ = q;
    const auto curves = std::min<Eigen::Index>(coordinates_.size(), 3);
    configuration_.assign(curves, DecimatedCurve(per_stretch_));
    right_.assign(energy_ ? 1 : curves, DecimatedCurve(per_stretch_));
    for (Eigen::Index i = 0; i < curves; ++i)
      phase_.push_back(Series{fmt::format("({}{}, p{})", manifold_.is_vector_space() ? "q" : "xi", i, i), {}, {}, false});
    if (energy_) initial_energy_ = values[0];
  }

  Manifold& manifold_;
  bool energy_;
  long per_stretch_, phase_every_, rows_ = 0;
  double initial_energy_ = 0.0;
  Eigen::VectorXd start_, coordinates_;
  std::vector<DecimatedCurve> configuration_, right_;
  std::vector<Series> phase_;
};

// The rows a run writes (spec "output.every"): step 0, every k-th step, and the last step.
long written_rows(const Scene& scene) {
  return scene.steps / scene.output_every + 1 + (scene.steps % scene.output_every != 0 ? 1 : 0);
}

// The run: the scene's trajectory (core/trajectory.hpp), observed and written at every step the
// scene observes or writes, the steps between taken in stretches (quiet_steps).
class Stepper {
 public:
  Stepper(const Scene& scene, Assembly& a, const RunOptions& options)
      : scene_(scene),
        a_(a),
        trajectory_(*a.map, a.q0, a.p0, a.t0, scene.step),
        observer_(scene.observe, *a.manifold, *a.lagrangian, a.v0, scene.solver, a.holonomic.get(),
                  &trajectory_.chaos()) {
    // megno and lyapunov: the deviation starts as the unit vector of equal components in (q, p)
    if (scene.observe.chaos()) trajectory_.track_deviation(Eigen::VectorXd::Ones(2 * a.map->dim()));
    if (options.out && options.out->extension() == ".h5")
      h5_ = std::make_unique<Hdf5Writer>(*options.out, scene.text);
    else if (options.out)
      csv_ = std::make_unique<CsvWriter>(*options.out);
    if (options.plot) plot_ = std::make_unique<PlotRecorder>(*a.manifold, scene.observe.energy, written_rows(scene));
    recorder_ = options.rows;
  }

  PlotRecorder* plot() { return plot_.get(); }

  // Runs every step; returns the failure that stopped it, if any.
  std::optional<Failure> run(bool quiet) {
    ProgressLine progress("step", scene_.steps, quiet);
    const auto start = Clock::now();
    std::optional<Failure> failure;
    try {
      start_output();
      while (trajectory_.steps() < scene_.steps) {
        if (const long quiet = quiet_steps(); quiet > 0) trajectory_.advance_checked(quiet);
        trajectory_.step();
        observe_and_write();
        progress.update(trajectory_.steps());
        if (interruption() != 0) break;
      }
    } catch (const StepFailure& e) {
      failure = Failure{e.step(), e.t(), e.residual(), e.what(), e.origin()};
    } catch (const NumericalFailure& e) {  // an observable that could not be formed
      failure = observable_failure(e);
    }
    outcome_.wall_seconds = std::chrono::duration<double>(Clock::now() - start).count();
    if (csv_) csv_->close();
    if (h5_) h5_->close();
    return failure;
  }

  const Trajectory& state() const { return trajectory_; }
  const RunOutcome& outcome() const { return outcome_; }
  const Observer& observer() const { return observer_; }

 private:
  void start_output() {
    if (csv_) csv_->header(csv_columns(a_.map->point_size(), a_.map->dim(), observer_));
    if (h5_) h5_->header(a_.map->point_size(), a_.map->dim(), observer_.columns());
    if (recorder_ != nullptr) recorder_->columns(a_.map->point_size(), a_.map->dim(), observer_.columns());
    observe_and_write();
  }

  // The steps before the next one that must be taken alone, observed or with its row due
  // (output.every, the last step), at most kStretch: those are taken in one stretch of the map's
  // advance() (its state in registers across them), the steps that `cost` and the benchmarks time.
  long quiet_steps() const {
    if (observing_) return 0;
    const long k = trajectory_.steps();
    long due = scene_.steps;
    if (csv_ || h5_ || plot_ || recorder_ != nullptr) due = std::min(due, (k / scene_.output_every + 1) * scene_.output_every);
    return std::clamp(due - k - 1, 0L, kStretch);
  }

  // An observable found wrong after its step completed: that step failed, from the time it started at.
  Failure observable_failure(const NumericalFailure& e) const {
    const long k = trajectory_.steps();
    return Failure{k, trajectory_.time_of(std::max(k - 1, 0L)), e.residual(), e.what(), e.origin()};
  }

  // Spec "output.every": every k-th step; step 0 and the last step are always written.
  void observe_and_write() {
    const long k = trajectory_.steps();
    const Eigen::VectorXd& q = trajectory_.q();
    const Eigen::VectorXd& held = trajectory_.p();
    observer_.observe(q.data(), held.data());
    // Never a non-finite number in the trajectory: an observable that overflows (energy of a
    // finite but huge state) ends the run like a non-finite state does.
    const auto& values = observer_.values();
    for (std::size_t i = 0; i < values.size(); ++i)
      if (!std::isfinite(values[i]))
        throw NumericalFailure(fmt::format("a non-finite {} ({})", observer_.columns()[i], values[i]), std::nan(""));
    if (energy_range_due(k)) observer_.check_energy_range(q.data(), held.data());
    const bool due = k % scene_.output_every == 0 || k == scene_.steps;
    if (!due) return;
    const Eigen::VectorXd& p = written_momentum(a_, q, held, written_);
    if (csv_)
      csv_->row(trajectory_.t(), q.data(), static_cast<int>(q.size()), p.data(), static_cast<int>(p.size()),
                values);
    if (h5_) h5_->row(trajectory_.t(), q.data(), static_cast<int>(q.size()), p.data(), static_cast<int>(p.size()), values);
    if (plot_) plot_->record(trajectory_.t(), q, p, values);
    if (recorder_ != nullptr) recorder_->row(trajectory_.t(), q.data(), p.data(), values);
  }

  // The energy's sane range (Observer::check_energy_range) is checked for a system without forces
  // at step 0, the last step, and every row where the energy is observed (it is at hand), else
  // every kRangeCheckRows-th row: a run that leaves it grows without bound and is caught within a
  // few rows, at the cost of one energy per kRangeCheckRows rows.
  bool energy_range_due(long k) {
    if (!a_.forces.empty()) return false;
    return scene_.observe.energy || rows_++ % kRangeCheckRows == 0 || k == scene_.steps;
  }
  static constexpr long kRangeCheckRows = 16;
  long rows_ = 0;

  const Scene& scene_;
  Assembly& a_;
  Eigen::VectorXd written_;  // the momentum as written (written_momentum), where it differs from the held
  Trajectory trajectory_;
  Observer observer_;
  RunOutcome outcome_;
  const bool observing_ = scene_.observe.energy || scene_.observe.momentum || scene_.observe.orthogonality ||
                          scene_.observe.constraint || scene_.observe.constraint_velocity || scene_.observe.chaos();
  std::unique_ptr<CsvWriter> csv_;
  std::unique_ptr<Hdf5Writer> h5_;
  std::unique_ptr<PlotRecorder> plot_;
  TrajectoryRecorder* recorder_ = nullptr;
};

// The failure's residual in the run record: its number, or where it is not finite (a non-finite
// value ended the run, or a residual was not applicable) the string "nan", "inf" or "-inf", which
// JSON has no number for (docs/hard-cases.md).
json residual_json(double residual) {
  if (std::isfinite(residual)) return residual;
  return std::isnan(residual) ? "nan" : residual > 0 ? "inf" : "-inf";
}

// Spec (docs/interface.md, departure_warning): an observed quantity the system conserves (the
// energy without forces; the momentum of a declared symmetry without forces or constraints) that
// departed from its start by more than the scene's fraction of its scale is said, so that a run
// whose step or coordinates fail (a chart's singularity, as the pole of spherical angles) does not
// pass silently.
std::vector<std::string> departure_warnings(const Scene& scene, const Assembly& a, const Observer& observer) {
  std::vector<std::string> warnings;
  const double fraction = scene.departure_warning;
  if (fraction <= 0.0 || !a.forces.empty()) return warnings;
  const auto say = [&](const char* what, double departure, double scale, const char* scale_name) {
    if (!(departure > fraction * scale) || scale <= 0.0) return;
    warnings.push_back(fmt::format(
        "the {} departed from its start by {:.3g}, {:.3g} of its scale {} = {:.3g} (departure_warning {:g}): the step "
        "does not resolve the motion, or the coordinates fail along it (a chart's singularity, as the pole of "
        "spherical angles); a smaller step tells which",
        what, departure, departure / scale, scale_name, scale, fraction));
  };
  if (scene.observe.energy) say("energy", observer.energy_error(), observer.energy_scale(), "|<p0, v0>| + |L(q0, v0)|");
  if (scene.observe.momentum && !a.holonomic)
    say("momentum", observer.momentum_error(), observer.momentum_scale(), "max(1, |J0|)");
  return warnings;
}

}  // namespace

RunOutcome run_scene(const Scene& scene, Assembly& assembly, const Registry& registry, const RunOptions& options) {
  Stepper stepper(scene, assembly, options);
  // A plugin fault or an interruption also leaves a run record, noting it (docs/security.md).
  const auto write_record = [&](const json& note) {
    json record = run_record(scene, assembly, stepper.observer(), stepper.state(), stepper.outcome(), registry);
    for (const auto& [key, value] : note.items()) record[key] = value;
    if (options.summary) write_json_file(*options.summary, record, "--summary");
    if (options.record != nullptr) *options.record = record;
  };
  std::optional<Failure> failure;
  try {
    failure = stepper.run(options.quiet);
  } catch (const PluginFault& e) {
    write_record({{"failure",
                   {{"step", stepper.state().steps() + 1}, {"t", stepper.state().t()}, {"plugin_fault", e.what()}}}});
    throw;
  }
  if (const int signal = interruption(); signal != 0 && !failure) {
    write_record({{"interrupted", {{"signal", signal_name(signal)}, {"steps_completed", stepper.state().steps()}}}});
    throw Interrupted(signal, fmt::format("after step {} of {} (t = {:.10g}); the trajectory ends with that step's "
                                          "row and the run record notes the interruption",
                                          stepper.state().steps(), scene.steps, stepper.state().t()));
  }
  if (failure)
    write_record({{"failure",
                   {{"step", failure->step},
                    {"t", failure->t},
                    {"residual", residual_json(failure->residual)},
                    {"message", failure->message}}}});
  else {
    const std::vector<std::string> warnings = departure_warnings(scene, assembly, stepper.observer());
    if (options.warnings)
      for (const auto& warning : warnings) fmt::print(stderr, "varia: warning: {}\n", warning);
    write_record(warnings.empty() ? json::object() : json{{"warnings", warnings}});
  }
  if (options.plot) stepper.plot()->write(*options.plot);
  if (failure)
    throw RunFailure(fmt::format("step {} (from t = {:.10g}) failed: {}; residual {:.3e}", failure->step, failure->t,
                                 failure->message, failure->residual),
                     failure->residual, failure->origin, failure->step, failure->t);
  // With the trajectory on stdout, the human summary goes to stderr.
  if (!options.quiet) print_human_summary(options.out && *options.out == "-" ? stderr : results(), scene, assembly,
                                          stepper.observer(), stepper.state(), stepper.outcome());
  return stepper.outcome();
}

}  // namespace varia::host
