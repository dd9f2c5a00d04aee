// The planar Morse chain of plugins/lagrangian/morse_chain.cpp, for the tests of the SDK's
// derivatives at sizes above the stack path: L, its gradient and its Hessian written by hand from
// the bond's derivatives (an independent reference), and the same L as one dense
// AutodiffLagrangian model over all of (q, v).
#pragma once

#include <Eigen/Core>
#include <cmath>

#include "../../plugins/lagrangian/morse.hpp"
#include "varia/sdk/autodiff_lagrangian.hpp"

namespace varia::testing {

struct MorseChainParameters {
  int particles = 30;
  double mass = 1.0, depth = 1.0, range = 1.0, rest_length = 1.0;
};

// L = m/2 |v|^2 - sum_i V(|x_{i+1} - x_i|), V(r) = D (1 - e)^2, e = exp(-a (r - r0)):
// V'(r) = 2 D a e (1 - e), V''(r) = 2 D a^2 e (2 e - 1). With d = x_{i+1} - x_i and u = d/r,
// dV/dx_{i+1} = V' u = -dV/dx_i, and the 2 x 2 block B = V'' u u^T + V'/r (I - u u^T) enters the
// Hessian of V at (i, i) and (i+1, i+1), and -B at (i, i+1) and (i+1, i).
struct MorseChainFormula {
  MorseChainParameters p;

  double value(const Eigen::VectorXd& q, const Eigen::VectorXd& v) const {
    double L = 0.5 * p.mass * v.squaredNorm();
    for (int i = 0; i + 1 < p.particles; ++i) {
      const double e = std::exp(-p.range * (bond(q, i).norm() - p.rest_length));
      L -= p.depth * (1 - e) * (1 - e);
    }
    return L;
  }
  Eigen::VectorXd gradient(const Eigen::VectorXd& q, const Eigen::VectorXd& v) const {
    const int n = 2 * p.particles;
    Eigen::VectorXd g = Eigen::VectorXd::Zero(2 * n);
    g.tail(n) = p.mass * v;
    for (int i = 0; i + 1 < p.particles; ++i) {
      const Eigen::Vector2d d = bond(q, i);
      const Eigen::Vector2d force = first(d.norm()) * d / d.norm();  // dV/dx_{i+1}
      g.segment<2>(2 * i) += force;
      g.segment<2>(2 * i + 2) -= force;
    }
    return g;
  }
  Eigen::MatrixXd hessian(const Eigen::VectorXd& q) const {
    const int n = 2 * p.particles;
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(2 * n, 2 * n);
    H.bottomRightCorner(n, n).diagonal().setConstant(p.mass);
    for (int i = 0; i + 1 < p.particles; ++i) {
      const Eigen::Vector2d d = bond(q, i);
      const double r = d.norm();
      const Eigen::Vector2d u = d / r;
      const Eigen::Matrix2d uu = u * u.transpose();
      const Eigen::Matrix2d B = second(r) * uu + first(r) / r * (Eigen::Matrix2d::Identity() - uu);
      H.block<2, 2>(2 * i, 2 * i) -= B;
      H.block<2, 2>(2 * i + 2, 2 * i + 2) -= B;
      H.block<2, 2>(2 * i, 2 * i + 2) += B;
      H.block<2, 2>(2 * i + 2, 2 * i) += B;
    }
    return H;
  }

 private:
  static Eigen::Vector2d bond(const Eigen::VectorXd& q, int i) { return q.segment<2>(2 * i + 2) - q.segment<2>(2 * i); }
  double first(double r) const {
    const double e = std::exp(-p.range * (r - p.rest_length));
    return 2 * p.depth * p.range * e * (1 - e);
  }
  double second(double r) const {
    const double e = std::exp(-p.range * (r - p.rest_length));
    return 2 * p.depth * p.range * p.range * e * (2 * e - 1);
  }
};

// The same L as one dense model: differentiated over all of (q, v) at once (in chunks above
// sdk::kStackVariables numbers).
struct DenseMorseChain : sdk::AutodiffLagrangian<DenseMorseChain> {
  explicit DenseMorseChain(MorseChainParameters p)
      : sdk::AutodiffLagrangian<DenseMorseChain>(2 * p.particles, 2 * p.particles),
        mass(p.mass),
        bond{p.depth, p.range, p.rest_length} {}
  template <class T>
  T lagrangian(const sdk::Vec<T>& q, const sdk::Vec<T>& v) const {
    T L = 0.5 * mass * v.dot(v);
    for (int i = 0; i + 3 < q.size(); i += 2) L -= bond(q(i), q(i + 1), q(i + 2), q(i + 3));
    return L;
  }
  bool constant_mass_matrix(double* M) const noexcept override {
    const int n = velocity_size();
    Eigen::Map<Eigen::MatrixXd>(M, n, n) = mass * Eigen::MatrixXd::Identity(n, n);
    return true;
  }
  double mass;
  plugins::MorseBond bond;
};

// A chain near its rest shape, bent and moving: particle i near (i r0, 0), seeded by `seed`.
inline void morse_chain_state(const MorseChainParameters& p, int seed, Eigen::VectorXd& q, Eigen::VectorXd& v) {
  const int n = 2 * p.particles;
  q.resize(n);
  v.resize(n);
  for (int i = 0; i < p.particles; ++i) {
    q(2 * i) = i * p.rest_length + 0.15 * std::sin(1.3 * i + seed);
    q(2 * i + 1) = 0.2 * std::cos(0.7 * i + 2.0 * seed);
    v(2 * i) = 0.3 * std::sin(2.1 * i + 0.5 * seed);
    v(2 * i + 1) = 0.25 * std::cos(1.7 * i + seed);
  }
}

}  // namespace varia::testing
