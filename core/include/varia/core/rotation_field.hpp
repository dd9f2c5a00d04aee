// The Euler-Lagrange (Euler-Poincare) vector field on TSO(3) of a Lagrangian of rigid-body form
// L(R, Omega) = 1/2 Omega . J Omega - V(R) (paper, sec. 2; the field that the comparison methods
// of Figure 1 integrate), in the embedding R^9 x R^3, y = (R row-major, Omega):
//   R' = R hat(Omega),   J Omega' = J Omega x Omega + M(R, Omega),   M = vee(R^T G - G^T R),
// with G = dL/dR the embedding gradient, so M is the left-trivialized dL/dR: the potential's
// torque, as in the Lie group velocity Verlet method. Runge-Kutta methods integrate it in the
// embedding and leave the group; a Lie group method sees TSO(3) = SO(3) x R^3 as a group, with
// the algebra element xi = (Omega, Omega') and y . exp(xi) = (R exp(xi_R), Omega + xi_Omega).
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

#include "varia/core/manifold.hpp"
#include "varia/core/mechanical_field.hpp"

namespace varia {

class RotationField final : public EulerLagrangeField {
 public:
  // Throws std::invalid_argument unless the manifold is SO(3)-shaped (9-number points,
  // 3-dimensional tangents, not a vector space) and the Lagrangian matches it, with a constant
  // 3 x 3 inertia.
  RotationField(const Manifold& manifold, LagrangianEvaluator& lagrangian);
  int size() const noexcept override { return 12; }
  Status eval(const double* y, double* f) noexcept override;
  Status eval(const Jet2* y, Jet2* f) noexcept override;
  Status jacobian(const double* y, double* f, double* df) noexcept override;

  int algebra_size() const noexcept override { return 6; }
  Status algebra(const double* y, double* xi) noexcept override;
  Status algebra(const Jet2* y, Jet2* xi) noexcept override;
  Status move(const double* y, const double* xi, double* moved) noexcept override;
  Status move(const Jet2* y, const Jet2* xi, Jet2* moved) noexcept override;

 private:
  // dL/dR and dL/dOmega at y into the workspace of T.
  const double* gradient(const double* y);
  const Jet2* gradient(const Jet2* y);
  // From the gradient g = [dL/dR, dL/dOmega] at y: writes R hat(Omega) (9 numbers, row-major)
  // to attitude unless it is null, and Omega' to rate.
  template <class T>
  void rates(const T* y, const T* g, T* attitude, T* rate) const;

  std::array<double, 12> gradient_{};
  std::vector<Jet2> gradient_jet_ = std::vector<Jet2>(12);
  Eigen::Matrix<double, 12, 12> hessian_;
};

}  // namespace varia
