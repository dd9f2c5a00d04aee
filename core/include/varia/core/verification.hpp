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

// What the parts declare, as the theorems need it.
struct Composition {
  enum class Construction { galerkin, shooting, one_step, lie_verlet } construction;
  int quadrature_order = 0;            // degree of exactness + 1 (0: no quadrature)
  bool quadrature_symmetric = false;
  int degree = 0;                      // Galerkin interpolation degree s
  bool control_times_symmetric = false;
  bool natural_chart = false;          // Galerkin on a Lie group: interpolation in the chart at q0
  int method_order = 0;                // one-step method order p
  bool method_self_adjoint = false;
  bool method_symplectic = false;      // declared by one-step plugins
  bool method_equivariant = false;     // under the Lagrangian's symmetry
  bool lagrangian_invariant = false;   // the Lagrangian declares a symmetry group
  bool forced = false;                 // non-conservative forces (Lagrange-d'Alembert principle)
};

struct Predictions {
  std::optional<bool> self_adjoint, g_invariant, momentum_conserved, symplectic, energy_bounded;
  std::optional<int> ld_order, global_order;
  std::string reason;  // the theorem each prediction comes from, for the report
};

// Galerkin (paper, sec. 2): order min(2s, quadrature order); self-adjoint for a symmetric rule and
// symmetric control times on a vector space (the chart at q0 of a Lie group is not symmetric in
// q0 and q1: no prediction there); G-invariant for an invariant L (equivariant natural-chart
// interpolant).
// Shooting (paper, sec. 3 theorem): order min(p, q); self-adjoint for a self-adjoint method and a
// symmetric rule; G-invariant for a G-equivariant method and an invariant L.
Predictions predict(const Composition& composition);

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

// Runs `steps` steps of size h from (q, p), calling observe(k, q, p) at every step (k = 0 first).
using Observer = std::function<void(long, const double*, const double*)>;
void run(DiscreteHamiltonianMap& map, std::vector<double> q, std::vector<double> p, double h,
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
