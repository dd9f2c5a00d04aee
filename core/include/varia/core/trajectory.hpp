// The trajectory driver: the one stepping loop of varia (`run`, `cost`, `verify` and the
// benchmarks all step through it). It carries the state (q_k, p_k, t_k) of a run of a discrete
// Hamiltonian map (paper, eq. IDEL: the map (q_k, p_k) -> (q_{k+1}, p_{k+1})) together with the
// time, so that every run starts at its own start time and a forced system's step k sees
// t_k = t_0 + k h (a product: no round-off accumulates in the time).
#pragma once

#include <Eigen/Core>
#include <string>

#include "varia/core/chaos_indicators.hpp"
#include "varia/core/discrete_hamiltonian_map.hpp"

namespace varia {

// A step that failed: the NumericalFailure of the map, or a non-finite state, with the step it
// happened in (the step from `step` - 1 to `step`) and the time that step started from.
class StepFailure : public NumericalFailure {
 public:
  StepFailure(const NumericalFailure& failure, long step, double t)
      : NumericalFailure(failure.what(), failure.residual(), failure.origin()), step_(step), t_(t) {}
  StepFailure(const std::string& what, double residual, long step, double t)
      : NumericalFailure(what, residual), step_(step), t_(t) {}
  long step() const { return step_; }
  double t() const { return t_; }

 private:
  long step_;
  double t_;
};

class Trajectory {
 public:
  // Starts at (q0, p0) at time t0, with steps of size h; allocates the state once.
  Trajectory(DiscreteHamiltonianMap& map, const Eigen::VectorXd& q0, const Eigen::VectorXd& p0, double t0,
             double h);

  const Eigen::VectorXd& q() const { return q_; }
  const Eigen::VectorXd& p() const { return p_; }
  double t() const { return time_of(steps_); }
  double time_of(long k) const { return t0_ + static_cast<double>(k) * h_; }  // t_k
  long steps() const { return steps_; }  // steps taken so far
  double h() const { return h_; }

  // From now on, every step also propagates the deviation vector w (2 dim() numbers, (dq; dp) in
  // the natural chart's coordinates, nonzero) by the map's exact tangent map (the map's
  // step_with_tangent), renormalized to unit length after each step, and the chaos indicators
  // (chaos_indicators.hpp) take its growth. advance() then steps one step at a time.
  void track_deviation(const Eigen::VectorXd& w);
  bool tracks_deviation() const { return tracking_; }
  const Eigen::VectorXd& deviation() const { return deviation_; }
  const ChaosIndicators& chaos() const { return chaos_; }

  // One step. On failure (StepFailure) the state stays the last good one.
  void step();
  // `count` steps with nothing observed in between (the map's advance: the loop that `cost` and
  // the benchmarks time, free to keep its state in registers). On failure (StepFailure naming the
  // last step of the stretch) the state is unspecified.
  void advance(long count);
  // `count` steps by advance(); where the stretch fails, it is stepped again from its start one
  // step at a time, so that the StepFailure names the step that failed and the state is the last
  // good one, as with step() (should those steps all succeed, the trajectory goes on from them).
  // `varia run` takes the steps it neither observes nor writes so.
  void advance_checked(long count);
  // Steps to `last` (a total count of steps), calling observe(*this) after every step; stops
  // early when observe returns false (an interrupted run).
  template <class Observe>
  void run_to(long last, Observe&& observe) {
    while (steps_ < last) {
      step();
      if (!observe(*this)) return;
    }
  }

 private:
  DiscreteHamiltonianMap& map_;
  Eigen::VectorXd q_, p_, q1_, p1_;
  Eigen::VectorXd q_start_, p_start_;  // advance_checked's state at the stretch's start
  bool tracking_ = false;
  Eigen::VectorXd deviation_, deviation1_;  // w before and after a step
  ChaosIndicators chaos_;
  double t0_, h_;
  long steps_ = 0;
};

}  // namespace varia
