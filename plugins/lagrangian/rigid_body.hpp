// What the rigid-body Lagrangians on SO(3) share (rigid_body.cpp, heavy_top.cpp): the position is
// the attitude R (9 numbers, row-major), the velocity the body angular velocity Omega (Rdot =
// R hat(Omega)), and the kinetic energy T = 1/2 Omega . J Omega with J = diag(inertia), the
// principal moments. J is the constant mass matrix, which is how the Lie group velocity Verlet
// construction reads it; the potential, if any, depends on R alone. Both Lagrangians are invariant
// under left multiplication R -> Q R (Omega unchanged) for Q in their symmetry group, whose
// Noether momentum is the spatial angular momentum pi = R J Omega or a component of it.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>

#include "varia/core/so3.hpp"
#include "varia/sdk/autodiff_lagrangian.hpp"

namespace varia::plugins {

// parameters[key], which must be 3 finite numbers (each > 0 when `positive`); `fallback` if absent.
inline Eigen::Vector3d vector3_parameter(const nlohmann::json& parameters, const char* key,
                                         bool positive, const Eigen::Vector3d& fallback) {
  if (!parameters.contains(key)) return fallback;
  const auto& value = parameters.at(key);
  const auto fail = [&] {
    throw std::invalid_argument(std::string("parameter '") + key + "' must be 3 " +
                                (positive ? "positive " : "finite ") + "numbers, got " +
                                value.dump());
  };
  if (!value.is_array() || value.size() != 3) fail();
  Eigen::Vector3d v;
  for (int i = 0; i < 3; ++i) {
    if (!value[i].is_number()) fail();
    v(i) = value[i].get<double>();
    if (!std::isfinite(v(i)) || (positive && !(v(i) > 0))) fail();
  }
  return v;
}

inline void require_so3(const sdk::Context& context, const char* type) {
  if (context.manifold == "SO3" && context.point_size == 9 && context.dim == 3) return;
  throw std::invalid_argument(std::string(type) + " needs manifold SO3, got " + context.manifold +
                              " with dim " + std::to_string(context.dim));
}

// A pseudo-random rotation from `seed`: exp(hat w) with w uniform in the cube [-pi, pi]^3, or
// about `axis` alone by an angle uniform in [-pi, pi] when an axis is given.
inline Eigen::Matrix3d random_rotation(unsigned seed, const Eigen::Vector3d* axis) {
  std::mt19937 engine(seed);
  std::uniform_real_distribution<double> angle(-std::numbers::pi, std::numbers::pi);
  Eigen::Vector3d w;
  if (axis != nullptr)
    w = angle(engine) * *axis;
  else
    for (int i = 0; i < 3; ++i) w(i) = angle(engine);
  return so3::exp(w);
}

template <class Model>
class RigidBodyLagrangian : public sdk::AutodiffLagrangian<Model, 9, 3> {
 public:
  RigidBodyLagrangian(const nlohmann::json& parameters, const sdk::Context& context,
                      const char* type)
      : inertia_(vector3_parameter(parameters, "inertia", true, Eigen::Vector3d::Ones())) {
    require_so3(context, type);
  }

  // T = 1/2 sum_i J_i Omega_i^2.
  template <class T>
  T kinetic(const sdk::Vec<T>& v) const {
    T sum = T(0.0);
    for (int i = 0; i < 3; ++i) sum += T(0.5 * inertia_(i)) * v(i) * v(i);
    return sum;
  }

  bool constant_mass_matrix(double* mass) const noexcept override {
    Eigen::Map<Eigen::Matrix3d>{mass} = inertia_.asDiagonal();
    return true;
  }

  // The lifted left action (Q R, Omega): the body velocity is left-invariant.
  Status act(unsigned seed, const double* q, const double* v, double* gq,
             double* gv) noexcept override {
    return sdk::guarded(this->error_, [&] {
      const Eigen::Matrix3d Q = random_rotation(seed, symmetry_axis());
      so3::to_row_major(Q * so3::from_row_major(q), gq);
      for (int i = 0; i < 3; ++i) gv[i] = v[i];
    });
  }

 protected:
  // The spatial angular momentum pi = R J Omega, the momentum map of left SO(3) multiplication.
  Eigen::Vector3d spatial_momentum(const double* q, const double* v) const {
    return so3::from_row_major(q) * inertia_.cwiseProduct(Eigen::Vector3d(v[0], v[1], v[2]));
  }
  // The axis of the symmetry rotations, or null for all of SO(3).
  virtual const Eigen::Vector3d* symmetry_axis() const noexcept = 0;

  Eigen::Vector3d inertia_;
};

}  // namespace varia::plugins
