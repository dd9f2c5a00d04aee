// The observables a scene asks for (spec: "observe"): energy E = <p, v> - L with v from the
// inverse Legendre transform, the Noether momentum J(q, v), ||I - R^T R|| on SO3, and the
// constraints' residuals max |g_i(q)| and max |(G(q) v)_i|, MEGNO and the largest Lyapunov
// exponent's estimate (from the trajectory's chaos indicators). Nothing that is not asked for is computed.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "scene.hpp"
#include "varia/abi/lagrangian.hpp"
#include "varia/abi/manifold.hpp"
#include "varia/core/chaos_indicators.hpp"
#include "varia/core/constraints.hpp"
#include "varia/core/mechanics.hpp"

namespace varia::host {

class Observer {
 public:
  // v0 is the initial velocity, the first warm start of the inverse Legendre transform (zero when
  // it is not given: the assembly forms v0 only where the scene observes the energy or momentum).
  // constraints: the system's (null without; needed for the constraint observables).
  Observer(const Observe& observe, const Manifold& manifold, Lagrangian& lagrangian, const Eigen::VectorXd& v0,
           const SolverOptions& options, HolonomicConstraints* constraints = nullptr,
           const ChaosIndicators* chaos = nullptr);
  // energy; momentum0..; orthogonality; constraint; constraint_velocity; megno; lyapunov
  // (chaos: the run's indicators, read at every observe(); needed for the last two)
  std::vector<std::string> columns() const;
  // Computes the observables at (q, p) into values() and updates the largest deviations from the
  // first values seen.
  void observe(const double* q, const double* p);
  const std::vector<double>& values() const { return values_; }
  double energy_error() const { return energy_error_; }
  double momentum_error() const { return momentum_error_; }
  double orthogonality_error() const { return orthogonality_error_; }
  // The largest constraint residuals seen (not changes: they are 0 on the constraint).
  double constraint_error() const { return constraint_error_; }
  // The scales of the first observation: |<p, v>| + |L(q, v)| for the energy (which bounds |E|),
  // max(1, max_i |J_i|) for the momentum, as `verify` measures it.
  double energy_scale() const { return energy_scale_; }
  double momentum_scale() const { return momentum_scale_; }
  double constraint_velocity_error() const { return constraint_velocity_error_; }
  const ChaosIndicators* chaos() const { return chaos_; }

  // The sane-range check of a run without forces: the flow conserves the energy and a variational
  // integrator keeps its error bounded (O(h^r) by backward error analysis), so an error beyond the
  // energy's own scale at the first check, |<p, v>| + |L| (which bounds |E| there), is not a
  // result but a failure: a step too large for the method, or step equations whose roots are not
  // continuous in h. Throws NumericalFailure saying so; a start where that scale is 0 is not checked.
  // Reuses the energy of the last observe() at the same point when the energy is observed.
  void check_energy_range(const double* q, const double* p);

 private:
  void update_errors();
  void set_scales(const double* q, const double* p);  // at the first observation
  double energy(const double* q, const double* p);  // with v from the inverse Legendre transform
  Observe what_;
  const Manifold& manifold_;  // its constraint_error is the orthogonality observable
  Lagrangian& lagrangian_;
  LagrangianEvaluator evaluator_;  // its own counters: observing does not count as the method's work
  SolverOptions options_;
  Eigen::VectorXd v_;
  int momentum_size_ = 0;
  std::vector<double> values_, initial_;
  double energy_error_ = 0.0, momentum_error_ = 0.0, orthogonality_error_ = 0.0;
  HolonomicConstraints* constraints_;
  double constraint_error_ = 0.0, constraint_velocity_error_ = 0.0;
  const ChaosIndicators* chaos_;
  double energy_scale_ = 0.0, momentum_scale_ = 1.0;
  double range_energy_ = 0.0, range_scale_ = -1.0;  // E and |<p, v>| + |L| at the first range check
};

}  // namespace varia::host
