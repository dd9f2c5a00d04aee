// The Galerkin map's tangent map (spec "Tangent maps and ensembles"), by the implicit function
// theorem on the step's own equations. With E_nu(q^0..q^s) = dS/dq^nu + f_d^nu (galerkin.hpp),
// the step solves
//   E_0 + p0 = 0,  E_nu = 0 (0 < nu < s)   for the unknowns z = (q^1..q^s),   p1 = E_s,
// so, with H = dE/dq the Hessian of the action (and the forces' Jacobian) in all control points,
// J = d(E_0..E_{s-1})/dz the step's exact Newton Jacobian, and a direction (dq0, dp0):
//   J dz = -(d(E_0..E_{s-1})/dq^0 dq0 + (dp0; 0)),   dq1 = dz's last block,
//   dp1 = dE_s/dq^0 dq0 + dE_s/dz dz.
#include <cmath>
#include <utility>

#include "varia/core/galerkin.hpp"

namespace varia {

std::string GalerkinDiscreteLagrangian::tangent_map_refusal() const {
  if (constraints_ != nullptr)
    return "the Galerkin construction's tangent map is not derived with constraints yet";
  return {};
}

void GalerkinDiscreteLagrangian::take_tangent_step(const double* q0, const double* p0, double t0, double h,
                                                   double* q1, double* p1, int count, const double* directions,
                                                   double* images) {
  take_step(q0, p0, t0, h, q1, p1);
  t_ = t0;
  control_points_of_step(q0, q1, h);
  const int n = n_, m = s_ * n_;
  using Strided = Eigen::Map<const Eigen::MatrixXd, 0, Eigen::OuterStride<>>;
  const Strided dq0(directions, n, count, Eigen::OuterStride<>(2 * n));
  const Strided dp0(directions + n, n, count, Eigen::OuterStride<>(2 * n));
  Eigen::Map<Eigen::MatrixXd, 0, Eigen::OuterStride<>> dq1(images, n, count, Eigen::OuterStride<>(2 * n));
  Eigen::Map<Eigen::MatrixXd, 0, Eigen::OuterStride<>> dp1(images + n, n, count, Eigen::OuterStride<>(2 * n));
  // The images from H (dense or sparse) and the LU of its Newton block J = H(0..m, n..n+m).
  const auto images_from = [&](const auto& H, const auto& lu) {
    tangent_rhs_.noalias() = -H.block(0, 0, m, n) * dq0;
    tangent_rhs_.topRows(n) -= dp0;
    tangent_points_.noalias() = lu.solve(tangent_rhs_);
    dq1 = tangent_points_.bottomRows(n);
    dp1.noalias() = H.block(m, 0, n, n) * dq0;
    dp1.noalias() += H.block(m, n, n, m) * tangent_points_;
  };
  if (!lagrangian_.sparse()) {
    action(h, Order::hessian, !forces_.empty());
    tangent_lu_.compute(hessian_.block(0, n, m, m));
    return images_from(hessian_, tangent_lu_);
  }
  // The full Jacobian in a structure of its own, so that the step's Newton keeps its analysed one.
  const auto swap_structures = [this] {
    std::swap(sparse_.first_unknown, tangent_sparse_.first_unknown);
    std::swap(sparse_.first_equation, tangent_sparse_.first_equation);
    std::swap(sparse_.blocks, tangent_sparse_.blocks);
    sparse_.matrix.swap(tangent_sparse_.matrix);
    sparse_.slots.swap(tangent_sparse_.slots);
    std::swap(sparse_.analyzed, tangent_sparse_.analyzed);
  };
  swap_structures();
  struct SwapBack {
    const decltype(swap_structures)& swap;
    ~SwapBack() { swap(); }
  } swap_back{swap_structures};
  prepare_sparse(0, 0, s_ + 1);
  action(h, Order::hessian, !forces_.empty());
  tangent_block_ = sparse_.matrix.block(0, n, m, m);
  tangent_sparse_lu_.compute(tangent_block_);
  if (tangent_sparse_lu_.info() != Eigen::Success)
    throw NumericalFailure("the Galerkin Newton Jacobian is singular at the step's solution (its tangent map): " +
                               tangent_sparse_lu_.lastErrorMessage(),
                           std::nan(""));
  images_from(sparse_.matrix, tangent_sparse_lu_);
}

}  // namespace varia
