// The rigid-body problems of the SO(3) tests and their converged reference solution, written
// independently of the library's SO(3) code (odeint's Dormand-Prince 5(4) on the equations in the
// embedding). A state is (R row-major, Pi), 12 numbers.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <boost/numeric/odeint.hpp>
#include <cmath>
#include <filesystem>
#include <memory>
#include <vector>

#include "core/fixtures.hpp"
#include "varia/core/discrete_hamiltonian_map.hpp"
#include "varia/abi/one_step.hpp"
#include "varia/sdk/conformance/loader.hpp"

namespace varia::testing {

using Eigen::Matrix3d;
using Eigen::Vector3d;

using State = std::array<double, 12>;  // R row-major, Pi

// The rigid body's equations, written independently of the library's SO(3) code:
//   R' = R hat(Omega),  Pi' = Pi x Omega + w Gamma x chi,  Omega = J^{-1} Pi,  Gamma = R^T e3.
struct RigidBodyEquations {
  Vector3d J;
  double w;
  Vector3d chi;
  void operator()(const State& y, State& dy, double) const {
    const Matrix3d R = so3::from_row_major(y.data());
    const Vector3d Pi(y[9], y[10], y[11]);
    const Vector3d Omega = Pi.cwiseQuotient(J);
    const Vector3d Gamma = R.row(2).transpose();
    so3::to_row_major(Matrix3d(R * so3::hat(Omega)), dy.data());
    const Vector3d dPi = Pi.cross(Omega) + w * Gamma.cross(chi);
    for (int i = 0; i < 3; ++i) dy[9 + i] = dPi(i);
  }
};

struct Problem {
  Top top;
  State start;
};

// The free body: J = (1, 2, 3); the heavy top: J = (1, 1.5, 0.8) with its weight off the axis.
inline Problem free_body() {
  Problem p{Top(Vector3d(1, 2, 3), 0.0, Vector3d::Zero()), {}};
  so3::to_row_major(so3::exp(Vector3d(0.1, 0.2, 0.3)), p.start.data());
  const Vector3d Pi = Vector3d(0.4, 0.8, -0.6).cwiseProduct(p.top.J);
  for (int i = 0; i < 3; ++i) p.start[9 + i] = Pi(i);
  return p;
}
inline Problem heavy_top() {
  Problem p{Top(Vector3d(1, 1.5, 0.8), 1.0, Vector3d(0.1, 0.2, 0.5)), {}};
  so3::to_row_major(so3::exp(Vector3d(0.5, -0.2, 0.1)), p.start.data());
  const Vector3d Pi = Vector3d(0.5, -0.3, 2.0).cwiseProduct(p.top.J);
  for (int i = 0; i < 3; ++i) p.start[9 + i] = Pi(i);
  return p;
}

// The converged reference: Dormand-Prince 5(4) at tolerance 1e-13.
inline State reference(const Problem& p, double t_end) {
  namespace odeint = boost::numeric::odeint;
  State y = p.start;
  odeint::integrate_adaptive(
      odeint::make_controlled<odeint::runge_kutta_dopri5<State>>(1e-13, 1e-13),
      RigidBodyEquations{p.top.J, p.top.w, p.top.chi}, y, 0.0, t_end, 1e-3);
  return y;
}

inline double distance(const State& a, const State& b) {
  double sum = 0.0;
  for (int i = 0; i < 12; ++i) sum += (a[i] - b[i]) * (a[i] - b[i]);
  return std::sqrt(sum);
}

// `steps` steps of h from start.
inline State integrate(DiscreteHamiltonianMap& map, const State& start, double h, long steps) {
  State y = start, next;
  for (long k = 0; k < steps; ++k) {
    map.step(y.data(), y.data() + 9, h, next.data(), next.data() + 9);
    y = next;
  }
  return y;
}

// The crouch-grossman one-step plugin of the given order (2 or 3), from the build tree.
inline std::shared_ptr<OneStepMethod> crouch_grossman(int order) {
  static const sdk::conformance::LoadedPlugin plugin(
      std::filesystem::path(VARIA_BUILD_DIR) / "lib/varia/plugins/one_step_crouch_grossman.so");
  return plugin.create<OneStepMethod>({{"order", order}});
}

inline Vector3d spatial_momentum(const State& y) {
  return so3::from_row_major(y.data()) * Vector3d(y[9], y[10], y[11]);
}

// The slope of log(error) against log(h) at t_end between the successive halvings of h in
// `steps`, smallest h last; make() returns a fresh map for each run.
template <class Make>
std::vector<double> observed_orders(const Problem& p, Make&& make, double t_end,
                                    std::vector<long> steps = {50, 100, 200, 400}) {
  const State exact = reference(p, t_end);
  std::vector<double> errors, orders;
  for (long n : steps) errors.push_back(distance(integrate(*make(), p.start, t_end / n, n), exact));
  for (std::size_t k = 1; k < errors.size(); ++k)
    orders.push_back(std::log2(errors[k - 1] / errors[k]) / std::log2(double(steps[k]) / steps[k - 1]));
  return orders;
}

}  // namespace varia::testing
