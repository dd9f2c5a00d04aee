// In-process pieces for the shooting tests: Lagrangians that declare their constant mass matrix,
// the Runge-Kutta methods and rules of the paper's examples, and convergence measurement.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "core/fixtures.hpp"
#include "varia/core/trajectory.hpp"
#include "varia/core/discrete_hamiltonian_map.hpp"
#include "varia/sdk/runge_kutta.hpp"

namespace varia::testing {

// The unit oscillator, exact solution q0 cos t + v0 sin t.
struct MassOscillator : Oscillator {
  bool constant_mass_matrix(double* mass) const noexcept override {
    mass[0] = 1.0;
    return true;
  }
};

// A planar central force, L = |v|^2/2 + 1/|q|: rotation invariant (SO(2) on R^2).
struct PlanarKepler : sdk::AutodiffLagrangian<PlanarKepler, 2, 2> {
  template <class T>
  T lagrangian(const sdk::Vec<T>& q, const sdk::Vec<T>& v) const {
    using std::sqrt;
    return T(0.5) * v.dot(v) + T(1.0) / sqrt(q.dot(q));
  }
  bool constant_mass_matrix(double* mass) const noexcept override {
    Eigen::Map<Eigen::Matrix2d>{mass}.setIdentity();
    return true;
  }
};

// The double pendulum (unit masses and lengths): L = v1^2 + 1/2 v2^2 + v1 v2 cos(q1 - q2) + 2 cos q1
// + cos q2, a configuration-dependent mass matrix, declared as none.
struct DoublePendulum : sdk::AutodiffLagrangian<DoublePendulum, 2, 2> {
  template <class T>
  T lagrangian(const sdk::Vec<T>& q, const sdk::Vec<T>& v) const {
    using std::cos;
    return v(0) * v(0) + 0.5 * v(1) * v(1) + v(0) * v(1) * cos(q(0) - q(1)) + 2.0 * cos(q(0)) + cos(q(1));
  }
};

inline sdk::RungeKutta rk4() { return {sdk::classic_rk4(), 4, false}; }
inline sdk::RungeKutta explicit_midpoint() { return {sdk::explicit_midpoint(), 2, false}; }
inline sdk::RungeKutta implicit_midpoint() { return {sdk::collocation_tableau({0.5}), 2, true}; }
// The 2-stage Gauss method (the paper's SRK4), nodes 1/2 -+ sqrt(3)/6.
inline sdk::RungeKutta gauss2() {
  const double d = std::sqrt(3.0) / 6;
  return {sdk::collocation_tableau({0.5 - d, 0.5 + d}), 4, true};
}
// The 3-stage Gauss method, nodes 1/2 -+ sqrt(15)/10 and 1/2: order 6.
inline sdk::RungeKutta gauss3() {
  const double d = std::sqrt(15.0) / 10;
  return {sdk::collocation_tableau({0.5 - d, 0.5, 0.5 + d}), 6, true};
}

inline FixedRule simpson() { return lobatto3(); }
inline FixedRule midpoint_rule() { return FixedRule({0.5}, {1.0}, 1); }

// The Euler-Maclaurin formula with two terms: h/2 (f(0) + f(h)) + h^2/12 (f'(0) - f'(h)).
struct EulerMaclaurin2 : FixedRule {
  EulerMaclaurin2() : FixedRule({0.0, 1.0}, {0.5, 0.5}, 3) {}
  int derivative_terms() const noexcept override { return 1; }
  const double* derivative_weights(int) const noexcept override { return correction; }
  double correction[2] = {1.0 / 12, -1.0 / 12};
};

// (q, p) after `steps` steps of size h from (q0, p0).
inline Eigen::VectorXd run(DiscreteHamiltonianMap& map, const Eigen::VectorXd& q, const Eigen::VectorXd& p,
                           double h, int steps) {
  Trajectory trajectory(map, q, p, 0.0, h);
  trajectory.advance(steps);
  Eigen::VectorXd state(2 * q.size());
  state << trajectory.q(), trajectory.p();
  return state;
}

// The least-squares slope of log(error) against log(h) over the points [first, last).
inline double fitted_order(const std::vector<double>& h, const std::vector<double>& error,
                           int first, int last) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const int count = last - first;
  for (int i = first; i < last; ++i) {
    const double x = std::log(h[i]), y = std::log(error[i]);
    sx += x;
    sy += y;
    sxx += x * x;
    sxy += x * y;
  }
  return (count * sxy - sx * sy) / (count * sxx - sx * sx);
}

}  // namespace varia::testing

// Compiled once, in tests/fixtures.cpp.
extern template class varia::sdk::AutodiffLagrangian<varia::testing::PlanarKepler, 2, 2>;
extern template class varia::sdk::AutodiffLagrangian<varia::testing::DoublePendulum, 2, 2>;

