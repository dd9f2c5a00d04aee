// SO(3) as a Lie group manifold, shared by the SO3 plugin (plugins/manifold/SO3.cpp) and the
// tests: the group's minimal API (Rotations) for the SDK's adapter (varia/sdk/lie_group.hpp), and
// RotationGroup, the manifold, whose chart at second order keeps its tuned form (so3::chart_jets:
// only exp and dexp at 3-variable jets; varia/core/so3.hpp has the mathematics).
#pragma once

#include <Eigen/LU>
#include <array>
#include <cmath>
#include <limits>

#include "varia/core/so3.hpp"
#include "varia/sdk/lie_group.hpp"

namespace varia::sdk::groups {

using so3::from_row_major;
using so3::to_row_major;

// A point is accepted when ||I - R^T R||_F and |det R - 1| are below this.
constexpr double kMembershipTolerance = 1e-9;

template <class T>
using RowMajor = Eigen::Matrix<T, 3, 3, Eigen::RowMajor>;

// Whether the 9 numbers R (row-major) are a rotation, to kMembershipTolerance; fills `why` when
// not. The check of SO(3)'s points and of the rotation part of SE(3)'s.
inline bool contains_rotation(const double* q, char* why, int why_size) {
  for (int i = 0; i < 9; ++i)
    if (!std::isfinite(q[i])) return explain(why, why_size, "entry %d of R is not finite", i);
  const Eigen::Matrix3d R = from_row_major(q);
  const double orthogonality = so3::orthogonality_error(R);
  if (orthogonality > kMembershipTolerance)
    return explain(why, why_size, "R is not orthogonal: ||I - R^T R|| = %.3g (tolerance %g)", orthogonality,
                   kMembershipTolerance);
  if (std::abs(R.determinant() - 1.0) > kMembershipTolerance)
    return explain(why, why_size, "R is a reflection, not a rotation: det R = %.17g", R.determinant());
  return true;
}

// The extended precision of the increments below: the x87 format's 64-bit significand on
// x86-64, IEEE quadruple precision (113 bits) on AArch64 Linux.
using Extended = long double;
static_assert(std::numeric_limits<Extended>::digits > std::numeric_limits<double>::digits,
              "the group increments need a long double wider than double");

// An Extended increment as its double part and the rest (Manifold::increment's dq, dq_low).
template <int Rows, int Columns>
void split(const Eigen::Matrix<Extended, Rows, Columns>& increment, double* high, double* low) {
  for (int r = 0; r < Rows; ++r)
    for (int c = 0; c < Columns; ++c) {
      const double h = static_cast<double>(increment(r, c));
      high[Columns * r + c] = h;
      low[Columns * r + c] = static_cast<double>(increment(r, c) - h);
    }
}

// R0 (exp(w) - I) (Manifold::increment of SO(3), and of SE(3)'s rotation), by Rodrigues' formula
// for exp(w) - I (so3::expm1) in Extended, as its double part and the rest: the same increment in
// double, rounded at every step with an error that repeats along a steady motion, carried R off
// SO(3) by about 2.5 eps |w|^2 a step (docs/lie-groups.md, "Long runs"). Returns R0 in Extended.
inline so3::Matrix3<Extended> rotation_increment(const double* R0, const double* w, double* dR, double* dR_low) {
  const so3::Matrix3<Extended> B = from_row_major(R0).cast<Extended>();
  split<3, 3>(B * so3::expm1(so3::Vector3<Extended>(w[0], w[1], w[2])), dR, dR_low);
  return B;
}

// The minimal API of SO(3) (varia/sdk/lie_group.hpp): R row-major, the algebra R^3 with the
// cross product as bracket.
struct Rotations {
  static constexpr int point_size = 9, dim = 3;
  template <class T>
  static void compose(const T* a, const T* b, T* ab) {
    Eigen::Map<RowMajor<T>>{ab} = Eigen::Map<const RowMajor<T>>(a) * Eigen::Map<const RowMajor<T>>(b);
  }
  // R^{-1} rather than R^T: the same for a rotation, but local stays the exact inverse of retract
  // for a point that carries round-off (so3::chart_local).
  static void inverse(const double* a, double* a_inverse) {
    to_row_major(from_row_major(a).inverse(), a_inverse);
  }
  template <class T>
  static void exp(const T* xi, T* g) {
    Eigen::Map<RowMajor<T>>{g} = so3::exp(so3::Vector3<T>(xi[0], xi[1], xi[2]));
  }
  template <class T>
  static void log(const T* g, T* xi) {
    Eigen::Map<so3::Vector3<T>>{xi} = so3::log(so3::Matrix3<T>(Eigen::Map<const RowMajor<T>>(g)));
  }
  template <class T>
  static void bracket(const T* a, const T* b, T* ab) {
    ab[0] = a[1] * b[2] - a[2] * b[1];
    ab[1] = a[2] * b[0] - a[0] * b[2];
    ab[2] = a[0] * b[1] - a[1] * b[0];
  }
};

// SO(3) with its natural chart at R0: retract R0 exp(hat xi) (Rodrigues), local log(R0^{-1} R).
class RotationGroup : public LieGroupManifold<Rotations> {
 public:
  Status retract(const double* q0, const double* xi, double* q) noexcept override {
    const Eigen::Vector3d w(xi[0], xi[1], xi[2]);
    to_row_major(from_row_major(q0) * so3::exp(w), q);
    return nullptr;
  }

  Status local(const double* q0, const double* q, double* xi) noexcept override {
    so3::chart_local(q0, q, xi);
    return nullptr;
  }

  Status chart(const double* q0, const double* xi, const double* xi_dot, Derivatives point,
               Derivatives velocity) noexcept override {
    const bool with_point = point.value != nullptr || point.gradient != nullptr || point.hessian != nullptr;
    const bool with_velocity =
        velocity.value != nullptr || velocity.gradient != nullptr || velocity.hessian != nullptr;
    so3::chart_jets(q0, xi, xi_dot, with_point ? point_.data() : nullptr, with_velocity ? velocity_.data() : nullptr,
                    point.hessian != nullptr, velocity.hessian != nullptr);
    if (with_point) store(point_.data(), 9, 6, point);
    if (with_velocity) store(velocity_.data(), 3, 6, velocity);
    return nullptr;
  }

  bool has_increment() const noexcept override { return true; }
  Status increment(const double* q0, const double* xi, double* dq, double* dq_low) noexcept override {
    rotation_increment(q0, xi, dq, dq_low);
    return nullptr;
  }

  bool contains(const double* q, char* why, int why_size) noexcept override {
    return contains_rotation(q, why, why_size);
  }

  bool has_constraint() const noexcept override { return true; }
  double constraint_error(const double* q) const noexcept override {
    return so3::orthogonality_error(from_row_major(q));
  }

 private:
  std::array<Jet2, 9> point_;
  std::array<Jet2, 3> velocity_;
};

}  // namespace varia::sdk::groups
