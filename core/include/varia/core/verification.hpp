// Measuring the properties that the paper's theorems predict for a composed integrator
// (`varia verify`): each function measures one property of a discrete Lagrangian or of its
// discrete Hamiltonian map; predict() says what the theorems promise from the declared
// properties of the parts. The host builds the objects and prints the report.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "varia/core/discrete_hamiltonian_map.hpp"
#include "varia/core/manifold.hpp"
#include "varia/core/mechanics.hpp"

namespace varia {

// What the theorems promise of a composed integrator (each construction states its own:
// host/src/constructions/); null where they say nothing.
struct Predictions {
  std::optional<bool> self_adjoint, g_invariant, momentum_conserved, symplectic, energy_bounded;
  std::optional<int> ld_order, global_order;
  std::string reason;  // the theorem each prediction comes from, for the report
};

// A least-squares slope of log(error) against log(h) that drops points at round-off (error below
// `floor`), pre-asymptotic points (leading points whose local slope differs from the next by
// more than 0.3) and a round-off plateau (trailing points whose local slope breaks away from the
// one before by more than 0.3), saying why for each.
struct OrderFit {
  double slope = 0.0;
  int used = 0;
  std::vector<std::string> dropped;
  std::vector<double> errors;  // all the errors, fitted or not
};
OrderFit fit_order(const std::vector<double>& h, const std::vector<double>& error, double floor);

// Sample pairs (q0, q1) near the diagonal: q0 = retract(q, small), q1 = retract(q0, h v + small).
struct SamplePair {
  std::vector<double> q0, q1;
};
std::vector<SamplePair> sample_pairs(Manifold& manifold, const double* q, const double* v, double h,
                                     int count);

// max |L_d(q0, q1; h) + L_d(q1, q0; -h)| / scale: zero when L_d is self-adjoint (paper, sec. 3).
double self_adjointness_residual(DiscreteLagrangian& Ld, const std::vector<SamplePair>& pairs,
                                 double h);
// max |L_d(g q0, g q1) - L_d(q0, q1)| / scale over pseudo-random g of the declared group.
double invariance_residual(DiscreteLagrangian& Ld, Lagrangian& lagrangian,
                           const std::vector<SamplePair>& pairs, double h);

// The exact discrete Lagrangian (paper, eq. exact_Ld_Jacobi) along the exact solution from
// (q0, v0): q1 = q(h) and L_d^E = int_0^h L dt by the given (fine) quadrature rule.
void exact_discrete_lagrangian(LagrangianEvaluator& lagrangian, const double* nodes,
                               const double* weights, int points, const double* q0,
                               const double* v0, double h, double* q1, double* LdE);

// Runs `steps` steps of size h from (q, p) at time t0 through the trajectory driver
// (trajectory.hpp), calling observe(k, q, p) at every step (k = 0 first).
using Observer = std::function<void(long, const double*, const double*)>;
void run(DiscreteHamiltonianMap& map, const Eigen::VectorXd& q, const Eigen::VectorXd& p, double t0, double h,
         long steps, const Observer& observe);

// The one-step map's Jacobian M = d(xi1, pi1)/d(xi0, pi0) in canonical coordinates of T*Q (the
// natural chart at q0 and its conjugate momenta pi = dexp_{-xi}^T p; (q, p) on a vector space), by
// central differences with Richardson extrapolation (test of a property, not inside any solve),
// and its symplecticity defect ||M^T J M - J||_max. `noise` is the change of the defect between
// two difference steps: the floor below which the defect means nothing.
struct SymplecticityDefect {
  double defect = 0.0, noise = 0.0;
};
SymplecticityDefect symplecticity_defect(DiscreteHamiltonianMap& map, Manifold& manifold,
                                         const double* q0, const double* p0, double h);

// Whether the energy error drifts: the largest error over the last quarter of the run against
// the largest over the first quarter (a bounded error gives a ratio near 1, a drift about 3 or
// more for a linear growth).
double drift_ratio(const std::vector<double>& energy_error);

}  // namespace varia
