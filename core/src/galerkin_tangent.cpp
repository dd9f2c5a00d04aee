// The Galerkin map's tangent map (spec "Tangent maps and ensembles"), by the implicit function
// theorem on the step's own equations. With E_nu(q^0..q^s) = dS/dq^nu + f_d^nu (galerkin.hpp),
// the step solves
//   E_0 + p0 = 0,  E_nu = 0 (0 < nu < s)   for the unknowns z = (q^1..q^s),   p1 = E_s,
// so, with H = dE/dq the Hessian of the action (and the forces' Jacobian) in all control points,
// J = d(E_0..E_{s-1})/dz the step's exact Newton Jacobian, and a direction (dq0, dp0):
//   J dz = -(d(E_0..E_{s-1})/dq^0 dq0 + (dp0; 0)),   dq1 = dz's last block,
//   dp1 = dE_s/dq^0 dq0 + dE_s/dz dz.
#include "varia/core/galerkin.hpp"

namespace varia {

std::string GalerkinDiscreteLagrangian::tangent_map_refusal() const {
  if (constraints_ != nullptr)
    return "the Galerkin construction's tangent map is not derived with constraints yet";
  if (lagrangian_.sparse())
    return "the Galerkin construction's tangent map is derived for a Lagrangian with a dense Hessian; this one "
           "declares a sparse Hessian (a composite)";
  return {};
}

void GalerkinDiscreteLagrangian::take_tangent_step(const double* q0, const double* p0, double t0, double h,
                                                   double* q1, double* p1, int count, const double* directions,
                                                   double* images) {
  if (const std::string refusal = tangent_map_refusal(); !refusal.empty()) throw std::logic_error(refusal);
  take_step(q0, p0, t0, h, q1, p1);
  t_ = t0;
  control_points_of_step(q0, q1, h);
  action(h, Order::hessian, !forces_.empty());
  const int n = n_, m = s_ * n_;
  using Strided = Eigen::Map<const Eigen::MatrixXd, 0, Eigen::OuterStride<>>;
  const Strided dq0(directions, n, count, Eigen::OuterStride<>(2 * n));
  const Strided dp0(directions + n, n, count, Eigen::OuterStride<>(2 * n));
  tangent_lu_.compute(hessian_.block(0, n, m, m));
  tangent_rhs_.noalias() = -hessian_.block(0, 0, m, n) * dq0;
  tangent_rhs_.topRows(n) -= dp0;
  tangent_points_.noalias() = tangent_lu_.solve(tangent_rhs_);
  Eigen::Map<Eigen::MatrixXd, 0, Eigen::OuterStride<>> dq1(images, n, count, Eigen::OuterStride<>(2 * n));
  Eigen::Map<Eigen::MatrixXd, 0, Eigen::OuterStride<>> dp1(images + n, n, count, Eigen::OuterStride<>(2 * n));
  dq1 = tangent_points_.bottomRows(n);
  dp1.noalias() = hessian_.block(m, 0, n, n) * dq0;
  dp1.noalias() += hessian_.block(m, n, n, m) * tangent_points_;
}

}  // namespace varia
