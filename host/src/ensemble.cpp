#include "ensemble.hpp"

#define OMPI_SKIP_MPICXX 1  // the C interface only (Open MPI's deprecated C++ bindings need libmpi_cxx)
#include <mpi.h>

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

// The ensemble: the scene (with --set applied), the specs, and what its file holds.
struct Plan {
  json document;
  std::string scene_text, vary_text;
  std::vector<VarySpec> varies;
  EnsembleLayout layout;
  std::vector<double> parameters;  // members x varies, row-major: the product, the first --vary slowest
};

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

// One member, run as `varia run` runs its scene, with nothing written: its status, final state and
// record numbers. Scenes are prepared one at a time (`prepare`: the scene's validators are shared);
// the runs themselves in parallel. Interrupted propagates (the member is not recorded).
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

// A failed member's line on stderr (by the process that ran it).
void say_failure(const Plan& plan, long member, const MemberResult& r, const std::string& message) {
  if (r.status == 0 || message.empty()) return;
  std::vector<std::string> values;
  for (int v = 0; v < plan.layout.varies; ++v)
    values.push_back(fmt::format("{}={}", printable(plan.varies[v].pointer), plan.parameters[member * plan.layout.varies + v]));
  fmt::print(stderr, "varia: ensemble: member {} ({}) exits {}: {}\n", member, fmt::join(values, ", "), r.status,
             printable(message));
}

// The members still to run, handed out one at a time (take), and the file their results go to
// (record), shared by this process's threads and, under mpirun, rank 0's service of the others.
class Dispatcher {
 public:
  Dispatcher(const Plan& plan, const std::vector<long>& todo, EnsembleFile& file, ProgressLine& progress)
      : plan_(plan), todo_(todo), file_(file), progress_(progress) {}
  // The next member, or -1: none left, or an interruption or a failed write stopped the ensemble.
  long take() {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (interruption() != 0 || failure_ || next_ >= todo_.size()) return -1;
    return todo_[next_++];
  }
  void record(long member, const MemberResult& r, const std::string& message) {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (failure_) return;
    try {
      file_.write(member, r);
    } catch (...) {
      failure_ = std::current_exception();
      return;
    }
    say_failure(plan_, member, r, message);
    progress_.update(++done_);
  }
  // Takes and runs members until none is left, with a registry of its own.
  void work(const CommonOptions& common) {
    Registry registry = make_registry(common);
    for (long member; (member = take()) >= 0;) {
      std::string message;
      try {
        const MemberResult r = run_member(plan_, member, registry, prepare_, message);
        record(member, r, message);
      } catch (const Interrupted&) {
        return;
      }
    }
  }
  // A failed write ends the command, once the threads are done.
  void rethrow() const {
    if (failure_) std::rethrow_exception(failure_);
  }
  const Plan& plan() const { return plan_; }
  long done() const { return done_; }

 private:
  const Plan& plan_;
  const std::vector<long>& todo_;
  EnsembleFile& file_;
  ProgressLine& progress_;
  std::mutex mutex_, prepare_;
  std::size_t next_ = 0;
  long done_ = 0;  // members recorded by this command
  std::exception_ptr failure_;
};

// The members on `threads` threads of this process.
void run_on_threads(Dispatcher& dispatcher, const CommonOptions& common, int threads) {
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back([&] { dispatcher.work(common); });
  dispatcher.work(common);
  for (auto& thread : pool) thread.join();
  dispatcher.rethrow();
}

// ---- across processes (mpirun) ----------------------------------------------------------------------
// Rank 0 runs members on --threads threads of its own, and on its main thread hands out members as
// the other ranks ask and writes their results. Each other rank runs members on --threads threads,
// its main thread talking to rank 0 for them (MPI from the main thread only: MPI_THREAD_FUNNELED).
// A message from a worker is [kind, member, status, t, q, p, numbers]: kind 0 asks for a member, 1
// returns a member's result and asks for the next, 2 says the worker is done (no member left for
// it, or interrupted). Rank 0 answers 0 and 1 with a member's index, or -1: no more.
enum Tag { kResult = 1, kWork = 2 };

std::size_t message_size(const EnsembleLayout& l) {
  return 4 + static_cast<std::size_t>(l.point_size + l.dim) + l.numbers.size();
}

void check_mpi(int code, const char* doing) {
  if (code == MPI_SUCCESS) return;
  char text[MPI_MAX_ERROR_STRING];
  int length = 0;
  MPI_Error_string(code, text, &length);
  throw std::runtime_error(fmt::format("MPI: {} failed: {}", doing, std::string(text, length)));
}

void master(Dispatcher& dispatcher, const CommonOptions& common, int workers, int threads) {
  const Plan& plan = dispatcher.plan();
  std::vector<std::thread> own;
  for (int t = 0; t < threads; ++t) own.emplace_back([&] { dispatcher.work(common); });
  const auto join = [&] {
    for (auto& thread : own) thread.join();
  };
  std::vector<double> message(message_size(plan.layout));
  const auto n = static_cast<long>(plan.layout.point_size), m = static_cast<long>(plan.layout.dim);
  try {
    for (int active = workers; active > 0;) {
      int arrived = 0;
      MPI_Status status;
      check_mpi(MPI_Iprobe(MPI_ANY_SOURCE, kResult, MPI_COMM_WORLD, &arrived, &status), "probing");
      if (arrived == 0) {  // a sleep, not a busy wait: the workers and rank 0's own thread share the cores
        std::this_thread::sleep_for(std::chrono::microseconds(200));
        continue;
      }
      check_mpi(MPI_Recv(message.data(), static_cast<int>(message.size()), MPI_DOUBLE, status.MPI_SOURCE, kResult,
                         MPI_COMM_WORLD, MPI_STATUS_IGNORE),
                "receiving a result");
      const int kind = static_cast<int>(message[0]);
      if (kind == 2) {
        --active;
        continue;
      }
      if (kind == 1) {
        MemberResult r;
        r.status = static_cast<int>(message[2]);
        r.t = message[3];
        r.q.assign(message.begin() + 4, message.begin() + 4 + n);
        r.p.assign(message.begin() + 4 + n, message.begin() + 4 + n + m);
        r.numbers.assign(message.begin() + 4 + n + m, message.end());
        dispatcher.record(static_cast<long>(message[1]), r, "");  // the worker said why it failed
      }
      long index = dispatcher.take();
      check_mpi(MPI_Send(&index, 1, MPI_LONG, status.MPI_SOURCE, kWork, MPI_COMM_WORLD), "handing out a member");
    }
  } catch (...) {
    join();
    throw;
  }
  join();
  dispatcher.rethrow();
}

// A worker rank's members: handed to its threads (members), their results back to the main thread
// (finished), which alone talks to rank 0.
struct WorkerQueue {
  struct Finished {
    long member;
    MemberResult result;
    bool interrupted = false;
  };
  std::mutex mutex;
  std::condition_variable work, done;
  std::deque<long> members;
  std::deque<Finished> finished;
  bool closed = false;  // no more members: the threads stop once the queue is empty
  int running = 0;      // threads not yet stopped
};

void worker_thread(const Plan& plan, const CommonOptions& common, WorkerQueue& queue, std::mutex& prepare) {
  Registry registry = make_registry(common);
  while (true) {
    long member = -1;
    {
      std::unique_lock<std::mutex> lock(queue.mutex);
      queue.work.wait(lock, [&] { return !queue.members.empty() || queue.closed; });
      if (queue.members.empty()) break;
      member = queue.members.front();
      queue.members.pop_front();
    }
    WorkerQueue::Finished f{member, {}, false};
    try {
      std::string text;
      f.result = run_member(plan, member, registry, prepare, text);
      say_failure(plan, member, f.result, text);
    } catch (const Interrupted&) {
      f.interrupted = true;
    }
    {
      const std::lock_guard<std::mutex> lock(queue.mutex);
      queue.finished.push_back(std::move(f));
    }
    queue.done.notify_one();
    if (f.interrupted) break;
  }
  {
    const std::lock_guard<std::mutex> lock(queue.mutex);
    --queue.running;
  }
  queue.done.notify_one();
}

// The main thread of a worker rank: one member in flight per thread, each result sent to rank 0 with
// the request for the next; when rank 0 has none left (or a thread was interrupted), the threads
// finish what they hold, and the rank says it is done.
void worker(const Plan& plan, const CommonOptions& common, int threads) {
  WorkerQueue queue;
  std::mutex prepare;
  std::vector<double> message(message_size(plan.layout), std::nan(""));
  const auto exchange = [&]() -> long {  // sends message, returns rank 0's answer
    check_mpi(MPI_Send(message.data(), static_cast<int>(message.size()), MPI_DOUBLE, 0, kResult, MPI_COMM_WORLD),
              "sending a result");
    long index = -1;
    check_mpi(MPI_Recv(&index, 1, MPI_LONG, 0, kWork, MPI_COMM_WORLD, MPI_STATUS_IGNORE), "receiving a member");
    return index;
  };
  bool closed = false;
  int in_flight = 0;
  const auto hand = [&](long index) {
    const std::lock_guard<std::mutex> lock(queue.mutex);
    if (index >= 0 && !closed) {
      queue.members.push_back(index);
      ++in_flight;
    } else {
      closed = queue.closed = true;
    }
  };
  message[0] = 0;
  for (int t = 0; t < threads && !closed; ++t) hand(exchange());
  queue.running = threads;
  std::vector<std::thread> pool;
  for (int t = 0; t < threads; ++t) pool.emplace_back([&] { worker_thread(plan, common, queue, prepare); });
  queue.work.notify_all();
  while (true) {
    std::unique_lock<std::mutex> lock(queue.mutex);
    queue.done.wait(lock, [&] { return !queue.finished.empty() || queue.running == 0; });
    if (queue.finished.empty()) break;
    WorkerQueue::Finished f = std::move(queue.finished.front());
    queue.finished.pop_front();
    --in_flight;
    lock.unlock();
    if (f.interrupted) {  // its member stays unrun (status -1): --resume runs it
      hand(-1);
    } else {
      const MemberResult& r = f.result;
      std::fill(message.begin(), message.end(), std::nan(""));
      message[0] = 1;
      message[1] = static_cast<double>(f.member);
      message[2] = r.status;
      message[3] = r.t;
      std::copy(r.q.begin(), r.q.end(), message.begin() + 4);
      std::copy(r.p.begin(), r.p.end(), message.begin() + 4 + plan.layout.point_size);
      std::copy(r.numbers.begin(), r.numbers.end(), message.begin() + 4 + plan.layout.point_size + plan.layout.dim);
      hand(exchange());
    }
    queue.work.notify_all();
  }
  for (auto& thread : pool) thread.join();
  message[0] = 2;
  check_mpi(MPI_Send(message.data(), static_cast<int>(message.size()), MPI_DOUBLE, 0, kResult, MPI_COMM_WORLD),
            "saying the worker is done");
}

// Started by mpirun with more than one process (Open MPI's environment says so).
int mpi_processes() {
  const char* size = std::getenv("OMPI_COMM_WORLD_SIZE");
  return size == nullptr ? 1 : std::atoi(size);
}

// MPI_Finalize on every path out of the command.
struct MpiSession {
  MpiSession() {
    int provided = 0;
    // the worker threads never call MPI: every call is funneled through a rank's main thread
    check_mpi(MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided), "starting");
  }
  ~MpiSession() { MPI_Finalize(); }
  int rank() const {
    int r = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &r);
    return r;
  }
  int size() const {
    int s = 1;
    MPI_Comm_size(MPI_COMM_WORLD, &s);
    return s;
  }
};

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
