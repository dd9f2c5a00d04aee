// Measuring the properties that the paper's theorems predict for a composed integrator
// (`varia verify`): each function measures one property of a discrete Lagrangian or of its
// discrete Hamiltonian map; predict() says what the theorems promise from the declared
// properties of the parts. The host builds the objects and prints the report.
#pragma once

#include <algorithm>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "varia/core/constraints.hpp"
#include "varia/core/discrete_hamiltonian_map.hpp"
#include "varia/abi/manifold.hpp"
#include "varia/core/mechanics.hpp"

namespace varia {

// What the theorems promise of a composed integrator (each construction states its own:
// host/src/constructions/); null where they say nothing.
struct Predictions {
  std::optional<bool> self_adjoint, g_invariant, momentum_conserved, symplectic, energy_bounded;
  std::optional<int> ld_order, global_order;
  // The orders are the theorems' lower bounds (order at least min(p, q)), which a particular system
  // may exceed (a Lagrangian constant along the flow makes any rule exact), not a declared order.
  bool orders_are_bounds = false;
  std::string reason;  // the theorem each prediction comes from, for the report
};

// A least-squares slope of log(error) against log(h) that drops points at round-off (error below
// `floor`), pre-asymptotic points (leading points whose local slope differs from the next by
// more than 0.3) and a round-off plateau (trailing points whose local slope falls below the one
// before by more than 0.3), saying why for each; local slopes span a factor 2 in h. The filters apply whenever three points
// remain to compare; the slope is fitted only on at least kMinimumFitPoints points (fitted()).
// Where the local slopes still creep geometrically towards their limit, the slope is that limit
// (Aitken's delta-squared on the last four local slopes), said in `extrapolated`.
constexpr int kMinimumFitPoints = 4;
struct OrderFit {
  double slope = 0.0;
  int used = 0;
  std::vector<std::string> dropped;
  std::vector<double> h, errors;  // all the step sizes and errors, fitted or not
  std::string extrapolated;       // how the slope was extrapolated, when it was
  // The last local slopes (three, or two when there are only two) still rise and were not
  // extrapolated: the fit may end before its asymptotic range, and its slope is then a lower bound
  // of the order. The slopes are those of every point above round-off down to the fit's last one,
  // the pre-asymptotic points dropped in front included: a short fit at the bottom of a rising
  // ladder rises with it.
  bool still_rising = false;
  // The largest minus the smallest local slope over the fitted points: well above the filters'
  // 0.3, the fit has no asymptotic range (the errors bend between the pre-asymptotic regime and
  // round-off) and its slope measures no order.
  double slope_spread = 0.0;
  // The largest fitted step size over the smallest: below a factor 2 no local slope can be formed,
  // and a slope over so narrow a range measures no order.
  double h_span = 0.0;
  bool fitted() const { return used >= kMinimumFitPoints; }
};
OrderFit fit_order(const std::vector<double>& h, const std::vector<double>& error, double floor);

// An order measured at step sizes it chooses in the asymptotic range above round-off: a ladder
// h_top 2^(-k/4) down to two points below `floor` (at most kLadderPoints), whose top is doubled
// (at most up to h_max) while the filters leave fewer than kMinimumFitPoints points or the largest
// error is within six decades of the floor; or at
// the `given` step sizes alone (varia verify --h). error_at(h) may adjust h (e.g. to whole steps to
// a final time); a NumericalFailure at a step size drops that point, saying so. When given,
// noise_at(h) is the round-off the error shows at h (which can grow as h shrinks: L_d near the
// diagonal loses digits as |q1 - q0|); a point whose error is within it counts as at round-off.
constexpr int kLadderPoints = 24;
using ErrorAt = std::function<double(double& h)>;
using NoiseAt = std::function<double(double h)>;
OrderFit measure_order(const ErrorAt& error_at, double h_top, double h_max, double floor,
                       const std::vector<double>& given, const NoiseAt& noise_at = {});

// A defect that should vanish (a self-adjointness, invariance or symplecticity residual, a drift
// of a conserved quantity), measured at decreasing step sizes. It counts as zero when it stays
// within `noise`, the round-off the measurement itself shows (or kNoiseSpread times the quantity's
// own round-off unit), where it cannot shrink with h; otherwise it is reported with its scaling: the
// log-log slope over every point, each taken at least at the noise (a slope of 1 or more: it
// shrinks with h, a term of the method).
constexpr double kNoiseSpread = 1e4;
struct DefectScaling {
  std::vector<double> h, values;
  double largest = 0.0, noise = 0.0;
  std::optional<double> slope;  // when the largest value is above the noise
  bool shrinks = false, zero = false;
  std::string describe() const;  // "4.1e-09 at h = 0.1, scaling as h^4.9" or "at round-off"
};
DefectScaling defect_scaling(const std::vector<double>& h, const std::vector<double>& values, double noise);

// Sample pairs (q0, q1) near the diagonal: q0 = retract(q, small), q1 = retract(q0, h v + small).
struct SamplePair {
  std::vector<double> q0, q1;
};
std::vector<SamplePair> sample_pairs(Manifold& manifold, const double* q, const double* v, double h,
                                     int count);

// max |L_d(q0, q1; h) + L_d(q1, q0; -h)| / scale: zero when L_d is self-adjoint (paper, sec. 3).
double self_adjointness_residual(DiscreteLagrangian& Ld, const std::vector<SamplePair>& pairs,
                                 double h);
// The round-off of L_d at the pairs, measured: max |L_d(q0', q1') - L_d(q0, q1)| / |L_d| where q'
// is q moved away and back (q exp(xi) exp(-xi)), equal to q but for round-off, or q1 moved by one
// unit in the last place of each coordinate (near the diagonal L_d magnifies its endpoints'
// rounding by |q| / |q1 - q0|). The floor of the residuals below and of ld_order's errors.
double round_off_of(DiscreteLagrangian& Ld, Manifold& manifold, const std::vector<SamplePair>& pairs, double h);
// What a solve stopped at `tolerance` may leave in L_d at the pairs, relative to |L_d|: a
// construction whose L_d comes out of an inner solve in which L_d is not stationary (shooting's
// boundary-value problem q^n(w0) = q1) meets q1 only to tolerance (1 + |q1|) (the Newton solver's
// stopping rule), which moves L_d by up to |D2 L_d|_1 times that. (Galerkin's L_d is stationary in
// its interior points: there this bounds a quadratic effect from above.)
double solver_noise_of(DiscreteLagrangian& Ld, const Manifold& manifold, const std::vector<SamplePair>& pairs, double h,
                       double tolerance);
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
using StateVisitor = std::function<void(long, const double*, const double*)>;
void run(DiscreteHamiltonianMap& map, const Eigen::VectorXd& q, const Eigen::VectorXd& p, double t0, double h,
         long steps, const StateVisitor& observe);

// The one-step map's Jacobian M = d(xi1, pi1)/d(xi0, pi0) in canonical coordinates of T*Q (the
// natural chart at q0 and its conjugate momenta pi = dexp_{-xi}^T p; (q, p) on a vector space), by
// central differences with Richardson extrapolation (test of a property, not inside any solve),
// and its symplecticity defect ||M^T J M - J||_max. `steps` holds the difference step of each
// coordinate (xi_1..xi_n, pi_1..pi_n), each on the scale of its coordinate; the defect is taken in
// the symplectic rescaling xi_j / a_j, pi_j a_j with a_j^2 = step(xi_j) / step(pi_j), which is the
// defect in coordinates measured in their own scales (dimensionless, and a light body's entries
// neither swamp nor vanish beside a heavy one's; unit steps leave the coordinates as they are).
// `noise` is the change of the defect between two difference steps: the floor below which the
// defect means nothing. With `tangent` (2n x k, its columns difference steps spanning the tangent
// space of a submanifold of T*Q at (q0, p0)), the defect is that of the form restricted to it:
// max |omega(M u_i, M u_j) - omega(u_i, u_j)| over its columns, each of unit length in the rescaled
// coordinates (constrained_tangent_basis: the constraint's cotangent bundle).
struct SymplecticityDefect {
  double defect = 0.0, noise = 0.0;
};
SymplecticityDefect symplecticity_defect(DiscreteHamiltonianMap& map, Manifold& manifold,
                                         const double* q0, const double* p0, double h,
                                         const Eigen::VectorXd& steps, const Eigen::MatrixXd& tangent = {});

// The same defect (coordinate directions) with M the map's exact tangent map (step_with_tangent:
// the implicit function theorem on the step's equations) at time t0, on a vector space. `noise`:
// what the solve leaves, M exact at a solution of the equations to the solver's `tolerance`, and
// round-off, (2n eps + tolerance) times the size of the rescaled form's entries.
SymplecticityDefect exact_symplecticity_defect(DiscreteHamiltonianMap& map, const double* q0, const double* p0,
                                               double t0, double h, const Eigen::VectorXd& steps, double tolerance);

// ||M^T J M - J||_max of a map's Jacobian M (2n x 2n, coordinates (q, p)): zero exactly when M is
// symplectic (the same defect as symplecticity_defect's, in unit scales).
double symplecticity_residual(const Eigen::MatrixXd& M);

// A basis of the tangent space at (q, p) of the constrained phase space {g(q) = 0, G(q) M^{-1} p =
// 0} (M the constant mass matrix, dense here: a test of a property): positions along an
// orthonormal basis z_j of ker G (times position_step) with the momentum change that keeps the
// hidden constraint, -G^T (G M^-1 G^T)^-1 K z_j, K = d(G(q) v)/dq at v = M^-1 p; and momenta M z_j
// (times momentum_step) at fixed q. 2n x 2(n - m); G must have full rank.
Eigen::MatrixXd constrained_tangent_basis(HolonomicConstraints& constraints, const Eigen::MatrixXd& mass,
                                          const double* q, const double* p, double position_step, double momentum_step);

// The energy error's drift over a run: a least-squares line through E - E0 against time; `trend`
// is its change over the run, `wander` the largest distance of the error from the line. A drift
// (non-symplectic methods: E - E0 grows like t h^p) is mostly trend; the bounded error of a
// symplectic method (a function of the state, h^p e(x)) is mostly wander, also when the motion
// is chaotic and the error wanders as the state explores the energy surface.
struct EnergyDrift {
  double trend = 0.0, wander = 0.0;
  // trend / (trend + wander): near 1 for a drift, small for a bounded error.
  double share() const { return trend / std::max(trend + wander, 1e-300); }
};
EnergyDrift energy_drift(const std::vector<double>& energy_error);

}  // namespace varia
