// The Kepler problem on R^2 or R^3: L(q, v) = |v|^2/2 + mu/|q|, so q'' = -mu q/|q|^3.
// L is invariant under rotations, SO(2) or SO(3), acting on q and v alike; its Noether momentum
// J = <dL/dv, xi q> is the angular momentum q x v (a scalar in the plane).
//
// Exact solution for bound orbits (energy < 0) through Lagrange's f and g functions in the
// difference of eccentric anomalies x = E - E0 (Danby, "Fundamentals of Celestial Mechanics",
// 2nd ed. 1988, sec. 6.8; Battin, "An Introduction to the Mathematics and Methods of
// Astrodynamics", 1999, sec. 4.3): with 1/a = 2/r0 - |v0|^2/mu, n = sqrt(mu/a^3),
// e cos E0 = 1 - r0/a and e sin E0 = (q0.v0)/sqrt(mu a), Kepler's equation
//   n t = x - e cos E0 sin x + e sin E0 (1 - cos x)
// is solved by Newton's method, and
//   q = f q0 + g v0,  v = f' q0 + g' v0,  r = a (1 - e cos E0 cos x + e sin E0 sin x),
//   f = 1 - a/r0 (1 - cos x),  g = t - (x - sin x)/n,
//   f' = -sqrt(mu a) sin x/(r r0),  g' = 1 - a/r (1 - cos x).
// Unbound orbits (energy >= 0) get an error Status, not an answer.
#include <Eigen/Geometry>
#include <boost/math/constants/constants.hpp>
#include <boost/math/tools/roots.hpp>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>

#include "support.hpp"
#include "varia/sdk/autodiff_lagrangian.hpp"

namespace {

constexpr double two_pi = boost::math::constants::two_pi<double>();
// Vectors and matrices of R^2 or R^3, without heap allocation.
using Vector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 3, 1>;
using Matrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 3, 3>;

// A pseudo-random rotation drawn from `seed`: about e3 by a uniform angle for dim 2 (its top-left
// 2 x 2 block is the planar rotation), from a uniform unit quaternion for dim 3 (Shoemake,
// "Uniform random rotations", Graphics Gems III, 1992).
Eigen::Matrix3d random_rotation(unsigned seed, int dim) {
  std::mt19937 engine(seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  if (dim == 2)
    return Eigen::AngleAxisd(two_pi * uniform(engine), Eigen::Vector3d::UnitZ()).matrix();
  const double u1 = uniform(engine), u2 = uniform(engine), u3 = uniform(engine);
  const double a = std::sqrt(1 - u1), b = std::sqrt(u1);
  return Eigen::Quaterniond(b * std::cos(two_pi * u3), a * std::sin(two_pi * u2),
                            a * std::cos(two_pi * u2), b * std::sin(two_pi * u3))
      .toRotationMatrix();
}

// The difference form of Kepler's equation, F(x) = x - ec sin x + es (1 - cos x) - M, with
// F'(x) = r/a > 0 for ec^2 + es^2 = e^2 < 1; its root lies in [M - 2, M + 2].
double eccentric_anomaly_step(double mean, double ec, double es) {
  const auto kepler = [&](double x) {
    return std::pair{x - ec * std::sin(x) + es * (1 - std::cos(x)) - mean,
                     1 - ec * std::cos(x) + es * std::sin(x)};
  };
  constexpr std::uintmax_t limit = 100;
  std::uintmax_t iterations = limit;
  const double x = boost::math::tools::newton_raphson_iterate(
      kepler, mean, mean - 2, mean + 2, std::numeric_limits<double>::digits, iterations);
  if (iterations >= limit)
    throw std::runtime_error("kepler: Newton's method on Kepler's equation did not converge");
  return x;
}

// Lagrange's coefficients (f, g, f', g') carrying (q0, v0) along its orbit for a time t, from
// r0 = |q0|, w0 = |v0|^2 and d0 = q0.v0 (the formulas at the top of this file).
struct LagrangeCoefficients {
  double f, g, fdot, gdot;
};
LagrangeCoefficients lagrange_coefficients(double mu, double r0, double w0, double d0, double t) {
  const double alpha = 2 / r0 - w0 / mu;  // 1/a
  if (!(alpha > 0))
    throw std::runtime_error(
        "kepler: the exact solution covers bound orbits only (energy < 0); this orbit has "
        "energy " +
        std::to_string(w0 / 2 - mu / r0));
  const double a = 1 / alpha, mean_motion = std::sqrt(mu * alpha * alpha * alpha);
  // The motion has period 2 pi/n: reduce t so that the mean anomaly n t lies in [-pi, pi].
  const double period = two_pi / mean_motion;
  const double tr = t - period * std::round(t / period);
  const double ec = 1 - r0 * alpha, es = d0 * std::sqrt(alpha / mu);
  const double x = eccentric_anomaly_step(mean_motion * tr, ec, es);
  const double one_minus_cos = 2 * std::pow(std::sin(x / 2), 2);  // without cancellation
  const double r = a * (1 - ec * std::cos(x) + es * std::sin(x));
  if (!(r > 0)) throw std::runtime_error("kepler: the orbit reaches the collision q = 0");
  return {1 - a / r0 * one_minus_cos, tr - (x - std::sin(x)) / mean_motion,
          -std::sqrt(mu * a) * std::sin(x) / (r * r0), 1 - a / r * one_minus_cos};
}

class Kepler final : public varia::sdk::AutodiffLagrangian<Kepler> {
 public:
  static constexpr const char* version = "1.0.0";
  static constexpr const char* parameter_schema = R"json({
    "$schema": "http://json-schema.org/draft-07/schema#",
    "type": "object",
    "properties": {
      "mu": {"type": "number", "exclusiveMinimum": 0, "default": 1,
             "description": "the gravitational parameter in L = |v|^2/2 + mu/|q|"}
    },
    "additionalProperties": false
  })json";
  static constexpr const char* properties = R"json({
    "lagrangian": "|v|^2/2 + mu/|q|",
    "energy": "|v|^2/2 - mu/|q|",
    "manifold": "Rn, dim 2 or 3",
    "symmetry": "SO(2) on R^2, SO(3) on R^3",
    "momentum_map": "angular momentum q x v (a scalar on R^2)",
    "exact_solution": true,
    "exact_solution_domain": "bound orbits (energy < 0); others get an error"
  })json";

  Kepler(const nlohmann::json& parameters, const varia::sdk::Context& context)
      : AutodiffLagrangian(dimension(context), dimension(context)),
        mu_(varia::plugins::positive_parameter(parameters, "mu", 1.0)) {}

  template <class T>
  T lagrangian(const varia::sdk::Vec<T>& q, const varia::sdk::Vec<T>& v) const {
    using std::sqrt;
    return T(0.5) * v.dot(v) + T(mu_) / sqrt(q.dot(q));
  }

  bool constant_mass_matrix(double* mass) const noexcept override {
    varia::plugins::write_scaled_identity(mass, velocity_size(), 1.0);
    return true;
  }

  const char* symmetry_group() const noexcept override {
    return velocity_size() == 2 ? "SO(2)" : "SO(3)";
  }
  int momentum_size() const noexcept override { return velocity_size() == 2 ? 1 : 3; }

  varia::Status momentum(const double* q, const double* v, double* J) noexcept override {
    return varia::sdk::guarded(error_, [&] {
      if (velocity_size() == 2) {
        J[0] = q[0] * v[1] - q[1] * v[0];
        return;
      }
      const Eigen::Map<const Eigen::Vector3d> position(q), velocity(v);
      Eigen::Map<Eigen::Vector3d>{J} = position.cross(velocity);
    });
  }

  varia::Status act(unsigned seed, const double* q, const double* v, double* gq,
                    double* gv) noexcept override {
    return varia::sdk::guarded(error_, [&] {
      const int n = velocity_size();
      const Matrix rotation = random_rotation(seed, n).topLeftCorner(n, n);
      const Vector x = Eigen::Map<const Vector>(q, n), w = Eigen::Map<const Vector>(v, n);
      Eigen::Map<Vector>(gq, n) = rotation * x;
      Eigen::Map<Vector>(gv, n) = rotation * w;
    });
  }

  bool has_exact_solution() const noexcept override { return true; }
  varia::Status exact_solution(const double* q0, const double* v0, double t, double* q,
                               double* v) noexcept override {
    return varia::sdk::guarded(error_, [&] {
      const int n = velocity_size();
      // Copies, since q and v may alias q0 and v0.
      const Vector x0 = Eigen::Map<const Vector>(q0, n), w0 = Eigen::Map<const Vector>(v0, n);
      const auto [f, g, fdot, gdot] =
          lagrange_coefficients(mu_, x0.norm(), w0.squaredNorm(), x0.dot(w0), t);
      Eigen::Map<Vector>(q, n) = f * x0 + g * w0;
      Eigen::Map<Vector>(v, n) = fdot * x0 + gdot * w0;
    });
  }

 private:
  static int dimension(const varia::sdk::Context& context) {
    varia::plugins::require_rn(context, "kepler", 2, 3);
    return context.dim;
  }

  double mu_;
};

}  // namespace

VARIA_PLUGIN(Kepler, lagrangian, kepler)
