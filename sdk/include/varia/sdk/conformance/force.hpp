// The force conformance suite (abi/force.hpp). The Jacobian the constructions' Newton solves use
// is checked against the force's own values:
//   - its pattern lies inside the n x (m + n) Jacobian [df/dq, df/dv];
//   - at random (t, q, v), the force alone equals the force with its Jacobian;
//   - a Taylor test along random directions (dq, dv) (taylor.hpp):
//     f(t, q + eps dq, v + eps dv) - f(t, q, v) - eps J (dq, dv) falls as eps^2. A wrong or missing
//     Jacobian entry fails it.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <random>
#include <sstream>

#include "varia/abi/force.hpp"
#include "varia/sdk/conformance/failures.hpp"
#include "varia/sdk/conformance/taylor.hpp"

namespace varia::sdk::conformance {

// f(t, z) at z = (q, v), and its Jacobian summed over the pattern into n x (m + n) when asked.
inline Eigen::VectorXd force_value(Force& force, double t, const Eigen::VectorXd& z, Eigen::MatrixXd* jacobian = nullptr) {
  const int m = force.position_size(), n = force.velocity_size();
  const int *rows = nullptr, *cols = nullptr;
  const int entries = force.jacobian_pattern(&rows, &cols);
  Eigen::VectorXd f(n), values(entries);
  check(force, force.evaluate(t, z.data(), z.data() + m, f.data(), jacobian ? values.data() : nullptr), "evaluate");
  if (jacobian != nullptr) {
    jacobian->setZero(n, m + n);
    for (int e = 0; e < entries; ++e) (*jacobian)(rows[e], cols[e]) += values(e);
  }
  return f;
}

// The whole suite on one force, at `trials` random points.
inline Failures check_force(Force& force, std::mt19937& engine, int trials = 5) {
  Failures failures;
  const int m = force.position_size(), n = force.velocity_size();
  const int *rows = nullptr, *cols = nullptr;
  const int entries = force.jacobian_pattern(&rows, &cols);
  for (int e = 0; e < entries; ++e)
    failures.expect(rows[e] >= 0 && rows[e] < n && cols[e] >= 0 && cols[e] < m + n, "Jacobian entry ", e, " (",
                    rows[e], ", ", cols[e], ") is outside the ", n, " x ", m + n, " Jacobian [df/dq, df/dv]");
  std::uniform_real_distribution<double> time(0.0, 10.0);
  for (int trial = 0; trial < trials && failures.empty(); ++trial) {
    const double t = time(engine);
    const Eigen::VectorXd z = random_point(m + n, engine);
    std::ostringstream where;
    where << "at t = " << t << ", (q, v) = [" << z.transpose() << "]: ";
    Failures at_point;
    at_point.set_context(where.str());
    try {
      Eigen::MatrixXd J;
      const Eigen::VectorXd f = force_value(force, t, z, &J);
      const double scale = std::max({1.0, f.lpNorm<Eigen::Infinity>(), J.lpNorm<Eigen::Infinity>()});
      at_point.expect((force_value(force, t, z) - f).lpNorm<Eigen::Infinity>() <= 1e-15 * scale,
                      "the force alone differs from the force with its Jacobian");
      for (int direction = 0; direction < 3 && at_point.empty(); ++direction) {
        const Eigen::VectorXd d = random_direction(m + n, engine);
        expect_taylor(
            at_point, [&](double eps) { return (force_value(force, t, z + eps * d) - f - eps * J * d).norm(); },
            scale, "the Jacobian is not the force's derivative in (q, v)");
      }
    } catch (const PluginFault& fault) {
      at_point.expect(false, "a call failed: ", fault.what());
    }
    failures.append(at_point);
  }
  return failures;
}

}  // namespace varia::sdk::conformance
