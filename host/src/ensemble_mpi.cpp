#include "ensemble_mpi.hpp"

#define OMPI_SKIP_MPICXX 1  // the C interface only (Open MPI's deprecated C++ bindings need libmpi_cxx)
#include <mpi.h>

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdlib>
#include <deque>
#include <stdexcept>
#include <thread>

namespace varia::host {

namespace {

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

}  // namespace

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

int mpi_processes() {
  const char* size = std::getenv("OMPI_COMM_WORLD_SIZE");
  return size == nullptr ? 1 : std::atoi(size);
}


MpiSession::MpiSession() {
  int provided = 0;
  // the worker threads never call MPI: every call is funneled through a rank's main thread
  check_mpi(MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided), "starting");
}

MpiSession::~MpiSession() { MPI_Finalize(); }

int MpiSession::rank() const {
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}

int MpiSession::size() const {
  int s = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &s);
  return s;
}

}  // namespace varia::host
