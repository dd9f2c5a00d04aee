// `varia ensemble` across the processes of mpirun (Open MPI): rank 0 hands out members and writes
// the file, the other ranks run them (ensemble_mpi.cpp). <mpi.h> stays in the source.
#pragma once

#include "ensemble_members.hpp"

namespace varia::host {

// The processes mpirun started (Open MPI's environment says so): 1 without mpirun.
int mpi_processes();

// MPI_Init_thread (MPI_THREAD_FUNNELED) when made, MPI_Finalize on every path out of the command.
class MpiSession {
 public:
  MpiSession();
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
  int rank() const;
  int size() const;
};

// Rank 0: runs members on `threads` threads of its own and serves `workers` other ranks.
void master(Dispatcher& dispatcher, const CommonOptions& common, int workers, int threads);
// Any other rank: runs the members rank 0 hands it on `threads` threads.
void worker(const Plan& plan, const CommonOptions& common, int threads);

}  // namespace varia::host
