// The discrete Hamiltonian map (paper, eq. IDEL): (q_k, p_k) -> (q_{k+1}, p_{k+1}), the one-step
// method that every construction provides, and the bookkeeping shared by all of them: evaluation
// counters, and (solve/newton.hpp) solver options, Newton statistics and the numerical failure.
#pragma once

#include <algorithm>
#include <utility>

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

// The time travels with the state: every step is taken from a state (q0, p0) at a time t0 that the
// caller passes (core/trajectory.hpp carries (q, p, t) through a run); a map keeps no clock. Only
// forced systems read t0 (time-dependent forces, force.hpp); the five-argument forms are the
// autonomous shorthand, a step from t0 = 0.
class DiscreteHamiltonianMap {
 public:
  virtual ~DiscreteHamiltonianMap() = default;
  virtual int point_size() const = 0;  // numbers per configuration point
  virtual int dim() const = 0;         // numbers per momentum
  // One step of size h from (q0, p0) at time t0 to (q1, p1). Throws NumericalFailure.
  void step(const double* q0, const double* p0, double t0, double h, double* q1, double* p1) {
    take_step(q0, p0, t0, h, q1, p1);
  }
  void step(const double* q0, const double* p0, double h, double* q1, double* p1) {
    take_step(q0, p0, 0.0, h, q1, p1);
  }
  // `steps` steps of size h from (q, p) at time t0, in place, with nothing observed in between
  // (the loop `varia cost` and the benchmarks time); q1, p1 are workspace of q's and p's sizes.
  // Throws NumericalFailure, and (q, p) are then unspecified: a caller that needs the last good
  // state steps with step() (core/trajectory.hpp does).
  void advance(double* q, double* p, double t0, double h, long steps, double* q1, double* p1) {
    take_steps(q, p, t0, h, steps, q1, p1);
  }
  void advance(double* q, double* p, double h, long steps, double* q1, double* p1) {
    take_steps(q, p, 0.0, h, steps, q1, p1);
  }
  // The tangent map (spec "Tangent maps and ensembles"): one step, as step() takes it, and the
  // images d(q1, p1)/d(q0, p0) dx of `count` directions dx = (dq; dp), the columns of `directions`
  // (2 dim() numbers each, column-major), into the columns of `images`. Exact: the implicit function
  // theorem on the step's own equations at their solution, not differences of steps. In the natural
  // chart's coordinates, which on a vector space are q's own. Throws std::logic_error where
  // tangent_map_refusal() is not empty.
  void step_with_tangent(const double* q0, const double* p0, double t0, double h, double* q1, double* p1, int count,
                         const double* directions, double* images) {
    if (const std::string refusal = tangent_map_refusal(); !refusal.empty()) throw std::logic_error(refusal);
    take_tangent_step(q0, p0, t0, h, q1, p1, count, directions, images);
  }
  // Empty where the map has its tangent map; else why it has none (the host refuses a scene that
  // asks for it with this reason).
  virtual std::string tangent_map_refusal() const { return "the tangent map of this construction is not derived yet"; }
  virtual const SolverStatistics& solver_statistics() const = 0;
  virtual const EvaluationCounters& evaluations() const = 0;

 protected:
  // Called only where tangent_map_refusal() is empty.
  virtual void take_tangent_step(const double* /*q0*/, const double* /*p0*/, double /*t0*/, double /*h*/,
                                 double* /*q1*/, double* /*p1*/, int /*count*/, const double* /*directions*/,
                                 double* /*images*/) {}
  virtual void take_step(const double* q0, const double* p0, double t0, double h, double* q1, double* p1) = 0;
  // The default takes one step after another, step k from t0 + k h (a product, not a sum: no
  // round-off accumulates in the time). A map may override it to keep its state in registers
  // across steps (the explicit Galerkin form does).
  virtual void take_steps(double* q, double* p, double t0, double h, long steps, double* q1, double* p1) {
    repeat_steps([this](auto... args) { take_step(args...); }, q, p, t0, h, steps, q1, p1);
  }
  // The loop of take_steps() by `step` (take_step's arguments): a map that overrides take_steps
  // to step by a non-virtual function passes it here. The steps go back and forth between (q, p)
  // and (q1, p1), the state copied once at the end if it is in (q1, p1), not once a step.
  template <class Step>
  void repeat_steps(Step&& step, double* q, double* p, double t0, double h, long steps, double* q1, double* p1) {
    double *from_q = q, *from_p = p, *to_q = q1, *to_p = p1;
    for (long k = 0; k < steps; ++k) {
      step(from_q, from_p, t0 + static_cast<double>(k) * h, h, to_q, to_p);
      std::swap(from_q, to_q);
      std::swap(from_p, to_p);
    }
    if (from_q == q) return;
    std::copy_n(from_q, point_size(), q);
    std::copy_n(from_p, dim(), p);
  }
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
