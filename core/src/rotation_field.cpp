#include "varia/core/rotation_field.hpp"

#include <Eigen/Geometry>
#include <stdexcept>

#include "varia/core/so3.hpp"

namespace varia {

namespace {

template <class T>
using RowMajor3 = Eigen::Matrix<T, 3, 3, Eigen::RowMajor>;

template <class T>
so3::Matrix3<T> matrix(const T* q) {
  return Eigen::Map<const RowMajor3<T>>(q);
}

LagrangianEvaluator& checked(const Manifold& manifold, LagrangianEvaluator& lagrangian) {
  if (manifold.point_size() != 9 || manifold.dim() != 3 || manifold.is_vector_space())
    throw std::invalid_argument(
        "the Euler-Lagrange field on a Lie group is implemented for SO(3): 9-number points, "
        "3-dimensional left-trivialized tangents");
  if (lagrangian.position_size() != 9 || lagrangian.velocity_size() != 3)
    throw std::invalid_argument("the Lagrangian's sizes do not match the manifold (9 + 3 numbers)");
  return lagrangian;
}

}  // namespace

RotationField::RotationField(const Manifold& manifold, LagrangianEvaluator& lagrangian)
    : EulerLagrangeField(checked(manifold, lagrangian)) {}

const double* RotationField::gradient(const double* y) {
  lagrangian_.gradient(y, y + 9, gradient_.data());
  return gradient_.data();
}

const Jet2* RotationField::gradient(const Jet2* y) {
  lagrangian_.gradient_jet(y, y + 9, nullptr, gradient_jet_.data());
  return gradient_jet_.data();
}

// R' = R hat(Omega), Omega' = J^{-1} (J Omega x Omega + vee(R^T G - G^T R)) (Euler-Poincare).
template <class T>
void RotationField::rates(const T* y, const T* g, T* attitude, T* rate) const {
  const so3::Matrix3<T> R = matrix(y);
  const so3::Vector3<T> omega(y[9], y[10], y[11]);
  if (attitude != nullptr) Eigen::Map<RowMajor3<T>>{attitude} = R * so3::hat(omega);
  const so3::Matrix3<T> J = mass_.cast<T>();
  const so3::Vector3<T> torque = so3::trivialize(R, matrix(g));
  Eigen::Map<so3::Vector3<T>>{rate} = inverse_mass_.cast<T>() * ((J * omega).cross(omega) + torque);
}

Status RotationField::eval(const double* y, double* f) noexcept {
  return guard([&] { rates(y, gradient(y), f, f + 9); });
}

Status RotationField::eval(const Jet2* y, Jet2* f) noexcept {
  return guard([&] { rates(y, gradient(y), f, f + 9); });
}

Status RotationField::algebra(const double* y, double* xi) noexcept {
  return guard([&] {
    std::copy(y + 9, y + 12, xi);
    rates(y, gradient(y), static_cast<double*>(nullptr), xi + 3);
  });
}

Status RotationField::algebra(const Jet2* y, Jet2* xi) noexcept {
  return guard([&] {
    std::copy(y + 9, y + 12, xi);
    rates(y, gradient(y), static_cast<Jet2*>(nullptr), xi + 3);
  });
}

namespace {

// (R, Omega) . exp(xi) = (R + R (exp(xi_R) - I), Omega + xi_Omega).
template <class T>
void move_state(const T* y, const T* xi, T* moved) {
  const so3::Matrix3<T> R = matrix(y);
  const so3::Vector3<T> w(xi[0], xi[1], xi[2]);
  Eigen::Map<RowMajor3<T>>{moved} = R + R * so3::expm1(w);
  for (int i = 0; i < 3; ++i) moved[9 + i] = y[9 + i] + xi[3 + i];
}

}  // namespace

Status RotationField::move(const double* y, const double* xi, double* moved) noexcept {
  return guard([&] { move_state(y, xi, moved); });
}

Status RotationField::move(const Jet2* y, const Jet2* xi, Jet2* moved) noexcept {
  return guard([&] { move_state(y, xi, moved); });
}

// Column c of df/dy, for the state coordinate y_c (R_ij at c = 3i + j, then Omega_a at 9 + a):
//   d(R hat Omega) = dR hat(Omega) + R hat(dOmega),
//   J dOmega' = (hat(J Omega) - hat(Omega) J) dOmega + vee(dA - dA^T),  dA = dR^T G + R^T dG,
// with dG the column of L's Hessian (y is ordered as L's (q, v)).
Status RotationField::jacobian(const double* y, double* f, double* df) noexcept {
  return guard([&] {
    lagrangian_.hessian(y, y + 9, gradient_.data(), hessian_.data());
    rates(y, gradient_.data(), f, f + 9);
    const Eigen::Matrix3d R = matrix(y), G = matrix(gradient_.data());
    const Eigen::Vector3d omega(y[9], y[10], y[11]);
    const Eigen::Matrix3d W = so3::hat(omega);
    const Eigen::Matrix3d gyroscopic = so3::hat(Eigen::Vector3d(mass_ * omega)) - W * mass_;
    Eigen::Map<Eigen::Matrix<double, 12, 12>> D(df);
    for (int c = 0; c < 12; ++c) {
      Eigen::Matrix3d dR = Eigen::Matrix3d::Zero();
      Eigen::Vector3d dOmega = Eigen::Vector3d::Zero();
      if (c < 9) dR(c / 3, c % 3) = 1.0;
      else dOmega(c - 9) = 1.0;
      const Eigen::Matrix3d dA = dR.transpose() * G + R.transpose() * matrix(hessian_.col(c).data());
      Eigen::Map<RowMajor3<double>>{D.col(c).data()} = dR * W + R * so3::hat(dOmega);
      D.col(c).tail(3) =
          inverse_mass_ * (gyroscopic * dOmega + so3::vee(Eigen::Matrix3d(dA - dA.transpose())));
    }
  });
}

}  // namespace varia
