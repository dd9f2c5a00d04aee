// The planar pendulum (the paper's "Planar Pendulum", sec. 7, there with m = l = g = 1):
// L(q, v) = m l^2/2 v^2 + m g l cos q on R^1, so q'' = -w0^2 sin q with w0 = sqrt(g/l).
//
// Exact solution through Jacobi elliptic functions (Lawden, "Elliptic Functions and
// Applications", 1989, sec. 5.2; DLMF 22.19.2). The conserved energy per m l^2,
// v^2/2 + w0^2 (1 - cos q), fixes the modulus
//   k^2 = v^2/(4 w0^2) + sin^2(q/2)
// (k < 1: libration, k > 1: rotation, k = 1: the separatrix), and
//   libration: sin(q/2) = k sn(u, k),  cos(q/2) = dn(u, k),  v = 2 k w0 cn(u, k),  u = w0 t + u0;
//   rotation:  q/2 = am(u, 1/k),  v = 2 s k w0 dn(u, 1/k),  u = s k w0 t + u0,  s = sign(v0);
// the separatrix is the rotation formula with modulus 1, am(u, 1) = gd(u) = atan(sinh u).
#include <boost/math/constants/constants.hpp>
#include <boost/math/special_functions/ellint_1.hpp>
#include <boost/math/special_functions/jacobi_elliptic.hpp>
#include <cmath>

#include "support.hpp"
#include "varia/sdk/autodiff_lagrangian.hpp"

namespace {

constexpr double pi = boost::math::constants::pi<double>();

// The incomplete elliptic integral of the first kind F(phi, k) = am^-1(phi), 0 <= k <= 1; for
// k = 1, F(phi, 1) = asinh(tan phi), |phi| <= pi/2 (DLMF 19.6.8).
double elliptic_f(double phi, double k) {
  return k < 1 ? boost::math::ellint_1(k, phi) : std::asinh(std::tan(phi));
}

// sn, cn and dn(u, k), 0 <= k < 1. Boost 1.74 forms dn as cos(T0)/cos(T1 - T0), which is 0/0
// where cn = 0 (u = K, the pendulum's turning points) and wrong there in the third digit; dn is
// taken instead from dn^2 = k'^2 + k^2 cn^2 (DLMF 22.6.1), a sum of positive terms.
struct Jacobi {
  double sn, cn, dn;
};
Jacobi jacobi(double u, double k) {
  double cn = 0, inaccurate_dn = 0;
  const double sn = boost::math::jacobi_elliptic(k, u, &cn, &inaccurate_dn);
  return {sn, cn, std::sqrt((1 - k) * (1 + k) + k * k * cn * cn)};
}

// Jacobi's amplitude am(u, k), 0 <= k <= 1, on the continuous branch, with dn(u, k) beside it:
// am(u + 2K) = am(u) + pi and dn(u + 2K) = dn(u) (DLMF 22.16.2, table 22.4.3), and on
// [-K, K] am = atan2(sn, cn) because cn >= 0 there. For k = 1, K is infinite and
// am(u, 1) = gd(u) = atan(sinh u), dn(u, 1) = sech u (DLMF 22.5.9, 22.16.3).
struct Amplitude {
  double am, dn;
};
Amplitude amplitude(double u, double k) {
  if (k == 1) return {std::atan(std::sinh(u)), 1 / std::cosh(u)};
  const double half_period = 2 * boost::math::ellint_1(k);
  const double turns = std::round(u / half_period);
  const Jacobi j = jacobi(u - turns * half_period, k);
  return {turns * pi + std::atan2(j.sn, j.cn), j.dn};
}

// x reduced to (-pi, pi] by a multiple of 2 pi.
double wrap(double x) {
  const double r = std::remainder(x, 2 * pi);
  return r == -pi ? pi : r;
}

class Pendulum final : public varia::sdk::AutodiffLagrangian<Pendulum, 1, 1> {
 public:
  static constexpr const char* version = "1.0.0";
  // The shooting construction's shot compiled with L inlined (docs/writing-plugins.md): SVIRK4's
  // step in bench_gni.
  static constexpr bool inline_shot = true;
  static constexpr const char* parameter_schema = R"json({
    "$schema": "http://json-schema.org/draft-07/schema#",
    "type": "object",
    "properties": {
      "mass": {"type": "number", "exclusiveMinimum": 0, "default": 1,
               "description": "m, the bob's mass"},
      "length": {"type": "number", "exclusiveMinimum": 0, "default": 1,
                 "description": "l, the massless rod's length"},
      "gravity": {"type": "number", "exclusiveMinimum": 0, "default": 1,
                  "description": "g, the gravitational acceleration (q = 0 hangs down)"}
    },
    "additionalProperties": false
  })json";
  static constexpr const char* properties = R"json({
    "lagrangian": "m l^2/2 v^2 + m g l cos q",
    "energy": "m l^2/2 v^2 - m g l cos q",
    "manifold": "Rn, dim 1",
    "symmetry": "none",
    "momentum_map": null,
    "exact_solution": true
  })json";

  Pendulum(const nlohmann::json& parameters, const varia::sdk::Context& context)
      : AutodiffLagrangian(),
        mass_(varia::plugins::positive_parameter(parameters, "mass", 1.0)),
        length_(varia::plugins::positive_parameter(parameters, "length", 1.0)),
        gravity_(varia::plugins::positive_parameter(parameters, "gravity", 1.0)),
        omega_(std::sqrt(gravity_ / length_)) {
    varia::plugins::require_rn(context, "pendulum", 1, 1);
  }

  template <class T>
  T lagrangian(const varia::sdk::Vec<T>& q, const varia::sdk::Vec<T>& v) const {
    using std::cos;
    return (0.5 * mass_ * length_ * length_) * v(0) * v(0) + (mass_ * gravity_ * length_) * cos(q(0));
  }

  bool constant_mass_matrix(double* mass) const noexcept override {
    varia::plugins::write_scaled_identity(mass, 1, mass_ * length_ * length_);
    return true;
  }

  bool has_exact_solution() const noexcept override { return true; }
  // Solved from q0 wrapped to (-pi, pi], then shifted back by the same multiple of 2 pi. q and v
  // may alias q0 and v0.
  varia::Status exact_solution(const double* q0, const double* v0, double t, double* q,
                               double* v) noexcept override {
    return varia::sdk::guarded(error_, [&] {
      const double start = wrap(q0[0]), shift = q0[0] - start;
      const double s = std::sin(start / 2), c = v0[0] / (2 * omega_);
      const double k = std::hypot(s, c);
      if (k < 1)
        librate(k, std::atan2(s, c), t, q, v);
      else
        rotate(k, start, v0[0] < 0 ? -1.0 : 1.0, t, q, v);
      q[0] += shift;
    });
  }

 private:
  // (sn, cn)(u0) = (s, c)/k, i.e. am(u0) = phi0 = atan2(s, c); q/2 = atan2(k sn, dn) is
  // accurate up to the amplitude, where asin(k sn) is not.
  void librate(double k, double phi0, double t, double* q, double* v) const {
    const double u = omega_ * t + boost::math::ellint_1(k, phi0);
    const Jacobi j = jacobi(u, k);
    q[0] = 2 * std::atan2(k * j.sn, j.dn);
    v[0] = 2 * k * omega_ * j.cn;
  }

  // am(u0, 1/k) = start/2, with |start/2| <= pi/2.
  void rotate(double k, double start, double sign, double t, double* q, double* v) const {
    const double modulus = 1 / k;
    const auto [am, dn] =
        amplitude(sign * k * omega_ * t + elliptic_f(start / 2, modulus), modulus);
    q[0] = 2 * am;
    v[0] = 2 * sign * k * omega_ * dn;
  }

  double mass_, length_, gravity_, omega_;
};

}  // namespace

VARIA_PLUGIN(Pendulum, lagrangian, pendulum)
