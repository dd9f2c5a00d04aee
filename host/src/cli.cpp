#include "cli.hpp"

#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <functional>
#include <new>
#include <system_error>

#include "commands.hpp"
#include "ensemble.hpp"
#include "cost.hpp"
#include "crash.hpp"
#include "errors.hpp"
#include "interrupt.hpp"
#include "memory.hpp"
#include "output.hpp"
#include "varia/core/discrete_hamiltonian_map.hpp"
#include "varia/abi/plugin_object.hpp"

namespace varia::host {

namespace {

// One line, whatever the message holds: control characters (newlines, terminal escapes, NUL)
// shown as \xNN (printable), and text quoted from the input cut to a bounded length. Never throws:
// a closed or full stderr loses the message, not the exit code.
void report(const std::string& message) {
  constexpr std::size_t kMaxShown = 2000;
  std::string line = "varia: error: " + printable(std::string_view(message).substr(0, kMaxShown));
  if (message.size() > kMaxShown) line += fmt::format("... ({} more bytes)", message.size() - kMaxShown);
  line += '\n';
  (void)std::fwrite(line.data(), 1, line.size(), stderr);
  (void)std::fflush(stderr);
}

// Standard descriptors that the caller closed are opened (stdin and stderr on /dev/null, stdout
// on /dev/full, so results written there fail loudly), so that no output file takes their
// number and receives diagnostics.
void open_standard_descriptors() {
  const char* devices[] = {"/dev/null", "/dev/full", "/dev/null"};
  for (int fd = 0; fd <= 2; ++fd)
    if (::fcntl(fd, F_GETFD) < 0 && errno == EBADF) {
      const int opened = ::open(devices[fd], fd == 0 ? O_RDONLY : O_WRONLY);
      if (opened >= 0 && opened != fd) {
        ::dup2(opened, fd);
        ::close(opened);
      }
    }
}

// Spec "Exit codes": 2 bad input, 3 plugin fault, 4 numerical failure.
int guarded(const std::function<int()>& command) {
  try {
    const int code = command();
    check_stdout();
    stop_if_interrupted("at the end of the command");
    return code;
  } catch (const Interrupted& e) {
    report(e.what());
    return 128 + e.signal();
  } catch (const std::system_error& e) {  // fmt printing to a stdout or stderr that refuses it
    report(fmt::format("stdout or stderr: the results cannot be written: {}", e.what()));
    return kExitInput;
  } catch (const std::exception&) {
    std::string message;
    const int code = exit_code_of(std::current_exception(), message);
    report(message);
    return code;
  }
}

struct Options {
  CommonOptions common;
  std::string scene;
  std::vector<std::string> scenes;
  RunOptions run;
  std::string run_out, run_summary, run_plot;
  LdOptions ld;
  TangentOptions tangent;
  EnsembleOptions ensemble;
  std::string ensemble_out, ensemble_plot;
  bool json = false;
  std::string verify_json, cost_out;
  std::vector<double> verify_h;
  bool verify_explain = false, verify_quiet = false;
  CostOptions cost;
};

CLI::App* subcommand(CLI::App& app, Options& o, const char* name, const char* description, const char* example) {
  CLI::App* sub = app.add_subcommand(name, description);
  sub->add_option("--plugin-path", o.common.plugin_paths,
                  "also search this directory for plugins (repeatable; searched after the bundled plugins, "
                  "before VARIA_PLUGIN_PATH)")
      ->type_name("DIR")
      ->allow_extra_args(false);  // one directory per flag: `--plugin-path DIR SCENE.json`
  sub->footer(example);
  return sub;
}

void add_settings(CLI::App* sub, Options& o) {
  sub->add_option("--set", o.common.settings,
                  "replace the value at a JSON pointer of the scene before it is checked, e.g. --set /step=0.05 or "
                  "--set '/initial/q=[0.5]' (repeatable, applied in order)")
      ->type_name("POINTER=JSON")
      ->allow_extra_args(false);
}

void add_scene(CLI::App* sub, Options& o, std::string& scene) {
  sub->add_option("SCENE", scene, "the scene file (JSON; its schema: scene.schema.json, see varia --help)")
      ->required()
      ->type_name("SCENE.json");
  add_settings(sub, o);
}

using Command = std::function<int()>;

void define_plugins(CLI::App& app, Options& o, Command& chosen) {
  auto* plugins = subcommand(app, o, "plugins",
                             "List every plugin found: kind, type name, version, file, declared properties and "
                             "parameters; files refused are listed after them with the reason.",
                             "Example:\n  varia plugins\n  varia plugins --json --plugin-path ./my-plugins");
  plugins->add_flag("--json", o.json, "print a JSON array of objects {kind, type, version, file, properties, "
                                      "parameter_schema}; refusals go to stderr");
  plugins->callback([&] { chosen = [&] { return command_plugins(o.common, o.json); }; });
}

void define_run(CLI::App& app, Options& o, Command& chosen) {
  auto* run = subcommand(app, o, "run",
                         "Simulate a scene. Without --out no trajectory is written (--out - writes the CSV to "
                         "stdout, and the human summary then goes to stderr). A short human summary is "
                         "printed at the end unless --quiet.",
                         "Example:\n  varia run scenes/default.json --out traj.csv --summary run.json");
  add_scene(run, o, o.scene);
  run->add_option("--out", o.run_out,
                  "write the trajectory here: CSV (t, q0.., p0.., observables), or HDF5 for a name ending in .h5 "
                  "(datasets t, q, p and one per observable; the scene as the root's attribute 'scene')")
      ->type_name("FILE.csv|FILE.h5");
  run->add_option("--summary", o.run_summary, "write the run record JSON here")->type_name("FILE.json");
  run->add_option("--plot", o.run_plot,
                  "draw three panels into this SVG (gnuplot): q(t) (q0..q2; on a Lie group the chart coordinates "
                  "xi of the start), the phase portrait (p_i against q_i), and |E - E0| on a log scale when the "
                  "energy is observed (else p0..p2); long runs are drawn in 1000 stretches of rows (their smallest "
                  "and largest values)")
      ->type_name("FILE.svg");
  run->add_flag("--quiet", o.run.quiet, "no progress line and no human summary");
  run->callback([&] {
    if (!o.run_out.empty()) o.run.out = o.run_out;
    if (!o.run_summary.empty()) o.run.summary = o.run_summary;
    if (!o.run_plot.empty()) o.run.plot = o.run_plot;
    chosen = [&] { return command_run(o.common, o.scene, o.run); };
  });
}

// The options of a command at one point (ld, tangent): the scene, --q0, a second vector (`second`:
// q1 or p0), --h and --json.
void add_point_options(CLI::App* command, Options& o, std::string& q0, const char* second, const char* second_help,
                       std::string& second_value, double& h, bool& json, const char* json_help) {
  add_scene(command, o, o.scene);
  command->add_option("--q0", q0, "the point q0, comma-separated")->required()->type_name("A,B,..");
  command->add_option(second, second_value, second_help)->required()->type_name("C,D,..");
  command->add_option("--h", h, "the step size")->required()->type_name("H");
  command->add_flag("--json", json, json_help);
}

void define_ld(CLI::App& app, Options& o, Command& chosen) {
  auto* ld = subcommand(app, o, "ld",
                        "Evaluate the scene's discrete Lagrangian L_d(q0, q1; h) and its derivatives D1 L_d, "
                        "D2 L_d at one point.",
                        "Example:\n  varia ld scenes/default.json --q0 1.3 --q1 1.25 --h 0.1 --json");
  add_point_options(ld, o, o.ld.q0, "--q1", "the second point, comma-separated", o.ld.q1, o.ld.h, o.ld.json,
                    "print {\"Ld\": x, \"D1\": [...], \"D2\": [...]}");
  ld->callback([&] { chosen = [&] { return command_ld(o.common, o.scene, o.ld); }; });
}

void define_tangent(CLI::App& app, Options& o, Command& chosen) {
  auto* tangent = subcommand(
      app, o, "tangent",
      "Take one step of the scene's discrete Hamiltonian map from (q0, p0) and print its tangent map "
      "d(q1, p1)/d(q0, p0), exact (the implicit function theorem on the step's own equations), rows q1 then p1, "
      "with its symplecticity defect.",
      "Example:\n  varia tangent scenes/default.json --q0 1.3 --p0 0.2 --h 0.1 --json");
  add_point_options(tangent, o, o.tangent.q0, "--p0", "the momentum, comma-separated", o.tangent.p0, o.tangent.h,
                    o.tangent.json, "print {\"q1\": [...], \"p1\": [...], \"jacobian\": [[...], ...]}");
  tangent->callback([&] { chosen = [&] { return command_tangent(o.common, o.scene, o.tangent); }; });
}

void define_ensemble(CLI::App& app, Options& o, Command& chosen) {
  auto* ensemble = subcommand(
      app, o, "ensemble",
      "Run one member per element of the product of the --vary specs (the first slowest), each the scene with "
      "its values set at their JSON pointers, run as `varia run` runs it, on --threads threads or, under "
      "mpirun -n K, across K processes of --threads threads each (rank 0 also hands members out and writes the file). FILE.h5 holds datasets "
      "parameters, status (each member's own exit code; -1: not run yet), final_t, final_q, final_p and one per "
      "run-record number (energy_error_max, megno_final, ...), and the scene and specs as attributes "
      "(docs/ensembles.md). A member that fails is recorded and the rest run; --resume runs only the members the "
      "file does not hold yet.",
      "Example:\n  varia ensemble scenes/chaos/double-pendulum-megno.json --set /t_end=20 \\\n"
      "      --vary /initial/q/0=linspace:-3:3:64 --vary /initial/q/1=linspace:-3:3:64 --out map.h5 --threads 2");
  add_scene(ensemble, o, o.scene);
  ensemble->add_option("--vary", o.ensemble.vary,
                       "POINTER=linspace:A:B:N, POINTER=list:A,B,... or POINTER=uniform:A:B:N:SEED (repeatable)")
      ->required()
      ->type_name("POINTER=SPEC");
  ensemble->add_option("--out", o.ensemble_out, "the ensemble's HDF5 file (a name ending in .h5)")
      ->required()
      ->type_name("FILE.h5");
  ensemble->add_option("--threads", o.ensemble.threads, "members run at once in each process (default 1)")
      ->type_name("N");
  ensemble->add_flag("--resume", o.ensemble.resume, "run only the members FILE.h5 does not hold yet");
  ensemble->add_option("--plot", o.ensemble_plot,
                       "the stability map as SVG: MEGNO over the grid of the two --vary (the scene observes megno)")
      ->type_name("FILE.svg");
  ensemble->add_flag("--quiet", o.ensemble.quiet, "no progress line and no summary line");
  ensemble->callback([&] {
    o.ensemble.out = o.ensemble_out;
    if (!o.ensemble_plot.empty()) o.ensemble.plot = o.ensemble_plot;
    chosen = [&] { return command_ensemble(o.common, o.scene, o.ensemble); };
  });
}

void define_validate(CLI::App& app, Options& o, Command& chosen) {
  auto* validate = subcommand(app, o, "validate",
                              "Check a scene against the scene schema and the plugins' parameter schemas, "
                              "and build its integrator, without running it.",
                              "Example:\n  varia validate scenes/default.json");
  add_scene(validate, o, o.scene);
  validate->callback([&] { chosen = [&] { return command_validate(o.common, o.scene); }; });
}

void define_verify(CLI::App& app, Options& o, Command& chosen) {
  auto* verify = subcommand(app, o, "verify",
                            "Check the theorem properties of the scene's discrete Lagrangian and integrator: predict "
                            "each from the declared properties of the parts (the paper's theorems), measure it, "
                            "and print both. Properties: self_adjoint, g_invariant, ld_order, global_order, "
                            "momentum_conserved, symplectic, energy_bounded. Exit 1 when a predicted property "
                            "does not hold or could not be measured.",
                            "Example:\n  varia verify scenes/default.json --json checks.json");
  add_scene(verify, o, o.scene);
  verify->add_option("--json", o.verify_json, "write the checks as JSON here")->type_name("FILE");
  verify->add_flag("--explain", o.verify_explain,
                   "print how each property was predicted and measured (the theorem, the fit, the points dropped "
                   "and why) after its row; without it the table gives only the reason a property was not measured");
  verify->add_option("--h", o.verify_h, "the step sizes the orders are fitted at, comma-separated: at least 4, no "
                                        "two taking the same number of steps to global_order's final time (20 times "
                                        "the largest step size), none more than 1e8 steps (default: chosen by verify "
                                        "in the asymptotic range above round-off)")
      ->delimiter(',')
      ->allow_extra_args(false)
      ->type_name("H,H,..");
  verify->add_flag("--quiet", o.verify_quiet,
                   "no progress line (on a terminal verify shows each run's step and the time it has left)");
  verify->callback([&] {
    chosen = [&] {
      return command_verify(o.common, o.scene, o.verify_json, o.verify_h, o.verify_explain, o.verify_quiet);
    };
  });
}

void define_cost(CLI::App& app, Options& o, Command& chosen) {
  auto* cost = subcommand(app, o, "cost",
                          "What accuracy costs in time: error, work and time across step sizes and methods, "
                          "as CSV and a plot.",
                          "Example:\n  varia cost scenes/pendulum-galerkin-s1.json scenes/pendulum-galerkin-s2.json "
                          "--out cost/");
  cost->add_option("SCENE", o.scenes, "scene files")->required()->type_name("SCENE.json");
  add_settings(cost, o);
  cost->add_option("--out", o.cost_out, "write cost.csv and cost.svg in this directory")->type_name("DIR");
  cost->add_option("--h", o.cost.h, "the step sizes to run, comma-separated (default: the scene's step times 4, 2, "
                                     "1, 1/2, ..., 1/16)")
      ->delimiter(',')
      ->allow_extra_args(false)
      ->type_name("H,H,..");
  cost->add_flag("--quiet", o.cost.quiet, "no progress line and no tables on stdout");
  cost->callback([&] {
    if (!o.cost_out.empty()) o.cost.out = o.cost_out;
    chosen = [&] { return command_cost(o.common, o.scenes, o.cost); };
  });
}

void define_commands(CLI::App& app, Options& o, Command& chosen) {
  define_plugins(app, o, chosen);
  define_run(app, o, chosen);
  define_ld(app, o, chosen);
  define_tangent(app, o, chosen);
  define_ensemble(app, o, chosen);
  define_validate(app, o, chosen);
  define_verify(app, o, chosen);
  define_cost(app, o, chosen);
}

// CLI11 reports a mistyped command as "A subcommand is required"; name it instead.
bool known_command(const CLI::App& app, const std::string& word) {
  const auto commands = app.get_subcommands([&](const CLI::App* sub) { return sub->get_name() == word; });
  return !commands.empty();
}

std::string command_names(const CLI::App& app) {
  std::string names;
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
    names += (names.empty() ? "" : ", ") + sub->get_name();
  return names;
}

}  // namespace

int main_cli(int argc, char** argv) {
  open_standard_descriptors();
  install_interrupt_handlers();
  install_crash_handlers();
  keep_freed_memory();
  return run_command_line(argc, argv, [](const std::string&) { return true; });
}

int run_command_line(int argc, char** argv, const std::function<bool(const std::string&)>& runs) {
  CLI::App app{"varia: variational integrators built from runtime-loaded plugins."};
  app.set_version_flag("--version", VARIA_VERSION);
  app.require_subcommand(1);
  app.footer(
      "Exit codes: 0 success, 1 (verify) a predicted property does not hold, 2 bad input, 3 plugin fault,\n"
      "4 numerical failure, 128 + N interrupted by signal N (130 SIGINT, 143 SIGTERM, 129 SIGHUP).\n"
      "Plugins are searched in the bundled directory, then --plugin-path, then VARIA_PLUGIN_PATH;\n"
      "directories a group may write are trusted under those named in VARIA_TRUSTED_PLUGIN_DIRS.\n"
      "The scene schema and example scenes: PREFIX/share/varia/scene.schema.json and\n"
      "PREFIX/share/varia/scenes/ (PREFIX: where varia is installed, bin/varia's parent), or\n"
      "schemas/scene.schema.json and scenes/ in the source tree.\n"
      "Example:\n  varia run scenes/default.json --out traj.csv --summary run.json");
  Options options;
  Command chosen;
  define_commands(app, options, chosen);
  if (argc > 1 && argv[1][0] != '-' && !known_command(app, argv[1])) {
    report(fmt::format("unknown command '{}'; the commands are: {}", argv[1], command_names(app)));
    return kExitInput;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    report(e.what());  // spec "Exit codes": a bad flag is bad input
    return kExitInput;
  }
  if (!runs(app.get_subcommands().front()->get_name())) return kExitOk;
  const CommandInFlight running;  // from here an exit() is a plugin's (crash.hpp)
  return guarded([&] {
    keep_stdout_for_results();
    return chosen();
  });
}

}  // namespace varia::host
