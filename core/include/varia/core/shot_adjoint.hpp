// The shooting construction's shot (shooting.hpp) at doubles, with the first derivatives the step
// needs from one reverse sweep instead of jets in every number of x = (eta, w0): where the shot is
// an explicit Runge-Kutta recurrence on R^n for a Lagrangian with a constant mass matrix M and no
// forces, in the lagrangian form (the state (q, v), the field (v, M^{-1} L_q)) or the hamiltonian
// form ((q, p), the field (M^{-1} p, L_q) at v = M^{-1} p).
//
// forward() propagates (q^0, w^0) = (q0, w0) through the nodes (the positions as offsets from q0,
// as the jets' propagation holds them) and keeps the stage points; it gives
// S = h sum_i b_i L(q^i, v^i), the far end's offset q^n - q0 and w^n. reverse(lambda) is the
// discrete adjoint of that recurrence for
//   F(eta, w0) = S - <lambda, q^n - (q0 + eta)>   (lambda frozen),
// i.e. of Phi = G - <lambda, B> at first order (shooting.hpp): dF/deta = G_eta - B_eta^T lambda,
// the step's momentum change D1 + lambda, and dF/dw0 = G_w - B_w^T lambda, which vanishes where
// lambda = B_w^{-T} G_w = D2 L_d. Each stage's adjoint is the field's transposed Jacobian times
// the stage's cotangent, (L_qq u, L_vq u) with u = M^{-1} k_v (or k_p): one Hessian-vector product
// of L (LagrangianEvaluator::hessian_product), so a sweep costs one gradient and one
// Hessian-vector product a stage, at any n. The eta-derivative gathers every evaluation's
// position adjoint: the field and L are evaluated at q0 + eta + offset.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "varia/abi/one_step.hpp"
#include "varia/core/mechanics.hpp"

namespace varia {

class ShotAdjoint {
 public:
  // nodes/weights: the shot's 0 = c_0 < ... < c_n = 1 and b_i (zero where the rule has no node);
  // inverse_mass: M^{-1}, n x n, kept by the caller.
  ShotAdjoint(LagrangianEvaluator& lagrangian, const Eigen::MatrixXd& inverse_mass, const RungeKuttaTableau& tableau,
              const std::vector<double>& nodes, const std::vector<double>& weights, bool cotangent);
  void forward(const double* q0, const double* w0, double h);
  // dF/deta into change, dF/dw0 into dw (n numbers each), after forward().
  void reverse(const double* lambda, double* change, double* dw);
  double action() const { return action_; }
  const Eigen::VectorXd& end_offset() const { return end_offset_; }
  const Eigen::VectorXd& end_w() const { return end_w_; }

 private:
  // The stage point (offsets, w) of interval k, stage j (j = 0: the node), and L's gradient there.
  double* point(int k, int j) { return points_.data() + (static_cast<Eigen::Index>(k) * stages_ + j) * 2 * n_; }
  double* gradient(int k, int j) { return gradients_.data() + (static_cast<Eigen::Index>(k) * stages_ + j) * 2 * n_; }
  // q_ and v_: the position q0 + offsets and the velocity of the state y (offsets, w).
  void take_point(const double* y);
  // L and its gradient at the state y.
  double evaluate(const double* y, double* gradient);
  // The field (v, M^{-1} L_q) or (v, L_q) from the state and L's gradient there.
  void field(const double* y, const double* gradient, double* f) const;
  // The transposed Jacobian of the field at y times k into out (2n numbers).
  void transposed_jacobian(const double* y, const double* k, double* out);
  // The node's h b_i dL/dy into the adjoint ybar and its dL/dq into the position adjoint.
  void add_node(double weight, const double* gradient, double* ybar);

  LagrangianEvaluator& lagrangian_;
  const Eigen::MatrixXd& inverse_mass_;
  RungeKuttaTableau tableau_;
  std::vector<double> nodes_, weights_;
  bool cotangent_;
  int n_, stages_, intervals_;
  double h_ = 0.0, action_ = 0.0;
  const double* q0_ = nullptr;
  // Workspace, sized once.
  Eigen::VectorXd points_, gradients_;  // every stage point and L's gradient there (the last node: interval n)
  Eigen::VectorXd K_, Kbar_, Ybar_, y_, ybar_, eta_bar_, q_, v_, u_, product_, end_offset_, end_w_;
};

}  // namespace varia
