// The Galerkin construction on a product of N unit spheres S2 in the natural chart at q0 (paper,
// sec. 2, "Natural charts"; docs/constraints.md): each factor's curve is
//   q_a(t) = Exp_{q0_a}(w_a(t)) = cos|w_a| q0_a + (sin|w_a| / |w_a|) w_a,
// the sphere's exponential map at q0_a (rotation of q0_a by the angle |w_a| towards w_a, the action
// exp(xi^) q0 of SO(3) with xi = q0 x w), w_a(t) the degree-s Lagrange interpolant in T_{q0_a}S2
// through w_a(0) = 0 and control points w_a^1..w_a^s, and
//   L_d(q0, q1) = ext h sum_i b_i L(q(c_i h), q'(c_i h)) over the internal control points, q1 = Exp_{q0}(w^s).
// The curves stay on the spheres between the control points; no multiplier enters.
//
// The discrete Legendre transforms. p1 = D2 L_d is the derivative in w^s mapped to T*_{q1}:
// p1 = Dphi (Dphi^T Dphi)^{-1} pi, pi = dA/dw^s, Dphi = dExp_{q0}(w^s) (3 x 2 a factor). -p0 = D1 L_d
// moves the chart's base point; the chart is SO(3)-equivariant, Exp_{R q0}(R w) = R Exp_{q0}(w), so
// rotating a factor's whole curve by exp(eta^) is a variation within the family, and the
// stationarity in the internal points gives, for every eta in R^3,
//   -p0 . (eta x q0) + p1 . (eta x q1) = h sum_i b_i (L_q . (eta x q_i) + L_v . (eta x q_i')),
// that is, on each factor, q0 x p0 = q1 x p1 - h sum_i b_i (q_i x L_q + q_i' x L_v): the discrete
// balance of angular momentum, which is D1 L_d without differentiating the chart in its base point.
// The step's equations in the 2 N s unknowns w^1..w^s: dA/dw^j = 0 (j < s), and that balance in
// T_{q0}. Their Jacobian is exact: the unknowns are the variables of second-order jets (abi/jet.hpp)
// through the chart, L's gradient and Hessian at each node complete A's Hessian and the balance's
// first derivatives by the chain rule; 2 N s <= kMaxJetVariables (the host refuses more).
// L_d itself (DiscreteLagrangian) solves the internal points' equations with w^s = Log_{q0}(q1), and
// gives D1 and D2 as covectors orthogonal to q0 and q1.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "varia/abi/jet.hpp"
#include "varia/abi/lagrangian.hpp"
#include "varia/abi/quadrature.hpp"
#include "varia/core/constraints.hpp"
#include "varia/core/discrete_hamiltonian_map.hpp"
#include "varia/core/galerkin.hpp"
#include "varia/core/mechanics.hpp"

namespace varia {

class SphereGalerkinMap final : public DiscreteLagrangian, public DiscreteHamiltonianMap {
 public:
  // `spheres` holds the N spheres' equations on R^(3N) (the manifold's defining constraint): the
  // momenta are returned in the constructions' form on the embedding, p = M v with G v = 0
  // (constraints.hpp, CotangentProjection), which needs the Lagrangian's constant mass matrix.
  // Throws std::invalid_argument for a rule with derivative terms, or more than kMaxJetVariables
  // unknowns.
  SphereGalerkinMap(Lagrangian& lagrangian, Quadrature& quadrature, std::vector<double> control_times,
                    SolverOptions options, HolonomicConstraints& spheres);
  ~SphereGalerkinMap() override;
  // L_d, D1 L_d, D2 L_d (any output may be null); q0 and q1 less than pi apart on each sphere. Points
  // off the spheres are taken onto them radially (L_d extended to R^3 \ 0 on each factor).
  void evaluate(const double* q0, const double* q1, double h, double* Ld, double* D1, double* D2) override;
  int point_size() const override { return 3 * spheres_count_; }
  int dim() const override { return 3 * spheres_count_; }
  int degree() const { return static_cast<int>(basis_.control_times.size()) - 1; }
  const SolverStatistics& solver_statistics() const override { return statistics_; }
  const EvaluationCounters& evaluations() const override { return lagrangian_.counters(); }
  // The number of unknowns of a step on N spheres at degree s (2 N s), which must not exceed
  // kMaxJetVariables.
  static int unknowns(int spheres, int degree) { return 2 * spheres * degree; }

 protected:
  void take_step(const double* q0, const double* p0, double t0, double h, double* q1, double* p1) override;

 private:
  struct Equations;
  // The tangent bases at q0 into bases_.
  void set_bases(const double* q0);

  LagrangianEvaluator lagrangian_;
  LagrangeBasis basis_;
  Eigen::VectorXd weights_;
  int spheres_count_;
  CotangentProjection projection_;
  NewtonSolver solver_, interior_solver_;  // the step's; L_d's (the internal points alone)
  SolverStatistics statistics_, interior_statistics_;
  DenseLinearization linearization_, interior_linearization_;
  // Workspace: the base point's tangent bases (3 x 2N), the unknowns (2N x s), the jets at a node.
  Eigen::MatrixXd bases_, unknowns_;
  std::vector<Jet2> variables_, q_, v_, end_point_, end_momentum_;
  Eigen::VectorXd correction_, no_momentum_, balance_residual_, base_, end_;
  // A node's z = (q, q'), L's gradient and Hessian there, dz/dW and H dz/dW.
  Eigen::VectorXd node_point_, node_gradient_;
  Eigen::MatrixXd node_hessian_, node_jacobian_, node_product_;
  // tau = h sum_i b_i (q_i x L_q + q_i' x L_v) on each factor (3N) and its derivatives in W (3N x D).
  Eigen::VectorXd balance_value_;
  Eigen::MatrixXd balance_jacobian_;
};

}  // namespace varia
