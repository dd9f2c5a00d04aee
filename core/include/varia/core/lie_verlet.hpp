// The Lie group velocity Verlet method, or Lie group variational integrator (LGVI), on SO(3)
// (paper, sec. 2 "Example: Lie group velocity Verlet"), for Lagrangians of rigid-body form
//   L(R, Omega) = 1/2 Omega . J Omega - V(R)
// with a constant inertia J, read from the Lagrangian's constant_mass_matrix(), and a potential V
// whose torque M = -T_e^* L_R dV/dR is the left-trivialized dL/dR at Omega = 0. The discrete
// Lagrangian is
//   L_d(R_k, R_{k+1}) = (1/h) tr((I - F_k) J_d) - h/2 (V(R_k) + V(R_{k+1})),  F_k = R_k^T R_{k+1},
// with J_d = tr(J)/2 I - J, and its discrete Hamiltonian map, in the body momentum Pi = J Omega,
//   h hat(Pi_k + h/2 M_k) = F_k J_d - J_d F_k^T           (paper, eq. findf, with g = h Pi + h^2/2 M)
//   R_{k+1} = R_k F_k,   Pi_{k+1} = F_k^T (Pi_k + h/2 M_k) + h/2 M_{k+1}.
// The implicit equation is solved by Newton's method on a 3-vector f, F = cay(f) (the paper's
// G_c) or F = exp(f) (the paper's G, Rodrigues), warm-started from the previous step's f. The
// updates R_k (F_k - I) and the momentum increment are added with compensated (Kahan) summation,
// carried over while each step starts where the last one ended, so that orthogonality and the
// spatial angular momentum R Pi stay at round-off without projecting back onto the group.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "varia/core/discrete_hamiltonian_map.hpp"
#include "varia/abi/manifold.hpp"
#include "varia/core/mechanics.hpp"

namespace varia {

enum class LieVerletSolver { cayley, exp };

class LieGroupVelocityVerlet : public DiscreteLagrangian, public DiscreteHamiltonianMap {
 public:
  // The manifold must be SO(3) (9-number points, 3-dimensional tangents, not a vector space) and
  // the Lagrangian must declare a constant 3 x 3 mass matrix J.
  LieGroupVelocityVerlet(Manifold& manifold, Lagrangian& lagrangian, LieVerletSolver solver,
                         SolverOptions options);

  void evaluate(const double* q0, const double* q1, double h, double* Ld, double* D1,
                double* D2) override;
  int point_size() const override { return 9; }
  int dim() const override { return 3; }
  // Throws NumericalFailure when F J_d - J_d F^T = hat(g) has no solution on the branch through
  // F = I: the step turns the body too far (about h |Omega| > 1 for a spin about a principal axis).
  std::string tangent_map_refusal() const override { return {}; }

 protected:
  void take_step(const double* q0, const double* p0, double t0, double h, double* q1, double* p1) override;
  // The implicit function theorem on the step's equation, in the natural charts at R0 and R1
  // (R0 exp(e hat(delta0)), Pi0 + e dPi0): with F perturbed as F exp(e hat(phi)),
  //   K phi = h dPi0 + h^2/2 dM0,   K e_a = vee(X_a - X_a^T), X_a = F hat(e_a) J_d
  // (hat(g) = F J_d - J_d F^T differentiated), then R1 = R0 F moves by delta1 = F^T delta0 + phi and
  //   dPi1 = -phi x F^T (Pi0 + h/2 M0) + F^T (dPi0 + h/2 dM0) + h/2 dM1,
  // dM the torque's derivative along the chart (torque_derivative).
  void take_tangent_step(const double* q0, const double* p0, double t0, double h, double* q1, double* p1, int count,
                         const double* directions, double* images) override;

 public:
  const SolverStatistics& solver_statistics() const override { return statistics_; }
  const EvaluationCounters& evaluations() const override { return lagrangian_.counters(); }
  // Residual norms of the last Newton solve, one per iteration.
  const std::vector<double>& last_residuals() const { return newton_.residuals(); }

 private:
  // Residual r(f) of the solver's equation for g, its Jacobian, and F - I.
  void residual(const Eigen::Vector3d& f, const Eigen::Vector3d& g, Eigen::Vector3d& r,
                Eigen::Matrix3d& jacobian, Eigen::Matrix3d& F_minus_I) const;
  struct Equation;  // the equation for f as a NewtonSolver system
  // Solves F J_d - J_d F^T = hat(g) for F on the branch through the identity; returns F - I.
  Eigen::Matrix3d solve(const Eigen::Vector3d& g);
  // M = the left-trivialized dL/dR at (R, Omega = 0): the potential's torque on the body.
  Eigen::Vector3d torque(const Eigen::Matrix3d& R);
  // The torque at R exp(e hat(delta)) differentiated in e: M = trivialize(R, dL/dR) is bilinear, so
  // dM = trivialize(R hat(delta), dL/dR) + trivialize(R, L_RR R hat(delta)), L's Hessian at (R, 0)
  // taken once per point (linearize_torque).
  struct TorqueLinearization {
    Eigen::Matrix3d R, gradient;
    Eigen::Matrix<double, 12, 12> hessian;
  };
  void linearize_torque(const Eigen::Matrix3d& R, TorqueLinearization& at);
  static Eigen::Vector3d torque_derivative(const TorqueLinearization& at, const Eigen::Vector3d& delta);
  TorqueLinearization tangent_end_;  // at the last tangent step's R1
  bool has_tangent_end_ = false;
  // tr(J_d (F - I)) and vee(X - X^T) for X = (F - I) J_d, free of the cancellations of F J_d.
  double trace_product(const Eigen::Matrix3d& F_minus_I) const;
  Eigen::Vector3d skew_part(const Eigen::Matrix3d& F_minus_I) const;
  Eigen::Matrix3d skew_part_derivative(const Eigen::Matrix3d& F) const;

  LagrangianEvaluator lagrangian_;
  LieVerletSolver solver_;
  SolverOptions options_;
  NewtonSolver newton_;
  SolverStatistics statistics_;
  Eigen::Matrix3d J_, Jd_;
  double reference_determinant_;  // det of the Jacobian at f = 0, g = 0: the identity's branch
  std::array<double, 12> gradient_{};  // [dL/dR row-major, dL/dOmega]

  // The state carried from one step to the next: the last solution f (warm start), the last
  // output and its torque, and the compensations of the two sums.
  Eigen::Vector3d f_ = Eigen::Vector3d::Zero();
  bool has_f_ = false;
  std::array<double, 12> last_state_{};
  double last_h_ = 0.0;
  bool has_last_ = false;
  Eigen::Vector3d last_torque_ = Eigen::Vector3d::Zero();
  Eigen::Matrix3d carry_R_ = Eigen::Matrix3d::Zero();
  Eigen::Vector3d carry_p_ = Eigen::Vector3d::Zero();
};

}  // namespace varia
