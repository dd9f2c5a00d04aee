// The Kepler problem on R^2 or R^3: L(q, v) = |v|^2/2 + mu/|q|, so q'' = -mu q/|q|^3.
// L is invariant under rotations, SO(2) or SO(3), acting on q and v alike; its Noether momentum
// J = <dL/dv, xi q> is the angular momentum q x v (a scalar in the plane).
//
// Exact solution for every orbit, bound or not, through Lagrange's f and g functions in the
// universal variable chi (Battin, "An Introduction to the Mathematics and Methods of
// Astrodynamics", 1999, sec. 4.5; Curtis, "Orbital Mechanics for Engineering Students", sec.
// 3.7): with alpha = 2/r0 - |v0|^2/mu (1/a; 0 on a parabola, < 0 on a hyperbola), z = alpha chi^2
// and Stumpff's functions C(z), S(z), the universal Kepler equation
//   sqrt(mu) t = (q0.v0)/sqrt(mu) chi^2 C + (1 - alpha r0) chi^3 S + r0 chi
// is solved by Newton's method (its derivative in chi is r > 0), and
//   q = f q0 + g v0,  v = f' q0 + g' v0,
//   f = 1 - chi^2 C/r0,  g = t - chi^3 S/sqrt(mu),  f' = sqrt(mu)/(r r0) (alpha chi^3 S - chi),
//   g' = 1 - chi^2 C/r,  r = chi^2 C + (q0.v0)/sqrt(mu) chi (1 - z S) + r0 (1 - z C),
// computed in the universal functions U_k (universal() below).
// One formula for every eccentricity: the eccentric-anomaly form it replaces lost 5 digits near
// e = 1 (a -> infinity: g = t - (x - sin x)/n cancels) and had no hyperbolic orbits.
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

// The universal functions U_k(chi) = chi^k c_k(alpha chi^2) (Battin, sec. 4.5), k = 0..3, from
// sin and cos (sinh and cosh) of y = sqrt(|alpha|) chi directly, so that U0 = cos y and
// U1 = sin y/sqrt(alpha) keep their own precision where they are small (at pericentre), and from
// the series of Stumpff's C and S (U2 = chi^2 C, U3 = chi^3 S) for |alpha chi^2| < 1, where the
// closed forms of U2 and U3 cancel.
template <class T>
struct Universal {
  T U0, U1, U2, U3;
};
template <class T>
Universal<T> universal(T alpha, T chi) {
  using std::abs, std::cos, std::cosh, std::pow, std::sin, std::sinh, std::sqrt;
  const T z = alpha * chi * chi;
  if (abs(z) < 1) {
    T C = 0, S = 0, term_c = 0.5, term_s = T(1) / 6;  // (-z)^k/(2k+2)!, (-z)^k/(2k+3)!
    for (int k = 0; k < 40 && (term_c != 0 || term_s != 0); ++k) {
      C += term_c;
      S += term_s;
      term_c *= -z / ((2 * k + 3) * (2 * k + 4));
      term_s *= -z / ((2 * k + 4) * (2 * k + 5));
    }
    const T U2 = chi * chi * C, U3 = chi * chi * chi * S;
    return {1 - alpha * U2, chi - alpha * U3, U2, U3};
  }
  const T root = sqrt(abs(alpha)), y = root * chi;
  if (alpha > 0) return {cos(y), sin(y) / root, 2 * pow(sin(y / 2), 2) / alpha, (y - sin(y)) / (alpha * root)};
  return {cosh(y), sinh(y) / root, 2 * pow(sinh(y / 2), 2) / -alpha, (sinh(y) - y) / (-alpha * root)};
}

// Lagrange's coefficients (f, g, f', g') carrying (q0, v0) along its orbit for a time t, from
// r0 = |q0|, w0 = |v0|^2 and d0 = q0.v0 (the formulas at the top of this file).
struct LagrangeCoefficients {
  double f, g, fdot, gdot;
};
LagrangeCoefficients lagrange_coefficients(double mu, double r0, double w0, double d0, double t) {
  const double alpha = 2 / r0 - w0 / mu, root_mu = std::sqrt(mu);
  // A bound motion has period 2 pi/n: reduce t so that the mean anomaly n t lies in [-pi, pi].
  if (alpha > 0) {
    const double period = two_pi / std::sqrt(mu * alpha * alpha * alpha);
    t -= period * std::round(t / period);
  }
  if (t == 0) return {1, 0, 0, 1};
  const double radial = d0 / root_mu;
  // Kepler's equation F(chi) = sqrt(mu) t and its derivative r, in the universal functions.
  const auto equation = [&](double chi) {
    const Universal u = universal<double>(alpha, chi);
    return std::pair{radial * u.U2 + u.U3 + r0 * u.U1 - root_mu * t, u.U2 + radial * u.U1 + r0 * u.U0};
  };
  // F increases (F' = r > 0) from F(0) = -sqrt(mu) t: bracket the root by doubling.
  double low = 0, high = 0, step = std::abs(root_mu * t) / r0;
  if (t > 0)
    while (equation(high = step).first < 0) step *= 2;
  else
    while (equation(low = -step).first > 0) step *= 2;
  constexpr std::uintmax_t limit = 200;
  std::uintmax_t iterations = limit;
  const double chi = boost::math::tools::newton_raphson_iterate(equation, 0.5 * (low + high), low, high,
                                                                std::numeric_limits<double>::digits, iterations);
  if (iterations >= limit) throw std::runtime_error("kepler: Newton's method on Kepler's equation did not converge");
  // One more Newton step and the coefficients in extended precision (long double): the root and r
  // are sums of terms larger than themselves near pericentre.
  using X = long double;
  const X a = alpha, R0 = r0, D = radial;
  Universal<X> u = universal<X>(a, chi);
  X r = u.U2 + D * u.U1 + R0 * u.U0;
  const X refined = chi - (D * u.U2 + u.U3 + R0 * u.U1 - X(root_mu) * X(t)) / r;
  u = universal<X>(a, refined);
  r = u.U2 + D * u.U1 + R0 * u.U0;
  if (!(r > 0)) throw std::runtime_error("kepler: the orbit reaches the collision q = 0");
  // g = t - U3/sqrt(mu), written with Kepler's equation so that nothing cancels against t.
  return {static_cast<double>(1 - u.U2 / R0), static_cast<double>((R0 * u.U1 + D * u.U2) / X(root_mu)),
          static_cast<double>(-X(root_mu) * u.U1 / (r * R0)), static_cast<double>(1 - u.U2 / r)};
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
    "exact_solution_domain": "every orbit: bound, parabolic and hyperbolic (universal variables)"
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
