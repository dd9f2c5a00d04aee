// The discrete Hamiltonian map (paper, eq. IDEL): (q_k, p_k) -> (q_{k+1}, p_{k+1}), the one-step
// method that every construction provides, and the bookkeeping shared by all of them: evaluation
// counters, and (solve/newton.hpp) solver options, Newton statistics and the numerical failure.
#pragma once

#include <algorithm>

#include <Eigen/Core>
#include <stdexcept>
#include <string>

#include "varia/core/solve/newton.hpp"

namespace varia {

// Plugin evaluations made so far (the run record's "evaluations").
struct EvaluationCounters {
  long lagrangian = 0;
  long gradient = 0;
  long hessian = 0;
  long force = 0;  // evaluations of the sum of the system's forces
};

class DiscreteHamiltonianMap {
 public:
  virtual ~DiscreteHamiltonianMap() = default;
  virtual int point_size() const = 0;  // numbers per configuration point
  virtual int dim() const = 0;         // numbers per momentum
  // One step of size h from (q0, p0) to (q1, p1). Throws NumericalFailure.
  virtual void step(const double* q0, const double* p0, double h, double* q1, double* p1) = 0;
  // `steps` steps of size h from (q, p), in place, with nothing observed in between (the loop
  // `varia cost` and the benchmarks time); q1, p1 are workspace of q's and p's sizes. A map may
  // override it to keep its state in registers across steps (the explicit Galerkin form does).
  // Throws NumericalFailure, and (q, p) are then unspecified: a caller that needs the last good
  // state steps with step().
  virtual void advance(double* q, double* p, double h, long steps, double* q1, double* p1) {
    for (long k = 0; k < steps; ++k) {
      step(q, p, h, q1, p1);
      std::copy_n(q1, point_size(), q);
      std::copy_n(p1, dim(), p);
    }
  }
  // The time at the start of the next step, for time-dependent forces (force.hpp); a map with
  // forces advances it by h on each step. Maps without forces ignore it.
  virtual void set_time(double /*t*/) {}
  virtual const SolverStatistics& solver_statistics() const = 0;
  virtual const EvaluationCounters& evaluations() const = 0;
};

// A discrete Lagrangian L_d(q0, q1; h) (paper, sec. 1) with its derivatives D1 L_d, D2 L_d (on a
// Lie group, left-trivialized). Constructions that have one implement both interfaces.
class DiscreteLagrangian {
 public:
  virtual ~DiscreteLagrangian() = default;
  virtual void evaluate(const double* q0, const double* q1, double h, double* Ld, double* D1,
                        double* D2) = 0;
};

}  // namespace varia
