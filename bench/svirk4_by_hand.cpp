#include "svirk4_by_hand.hpp"

#include <cmath>
#include <stdexcept>

#include "support.hpp"

namespace varia::bench {

namespace {

// A second-order jet in x = (eta, w0), written out: the value, the gradient and the three
// distinct second derivatives (ee, ew, ww), every operation inline.
struct J {
  double v = 0, g0 = 0, g1 = 0, h00 = 0, h01 = 0, h11 = 0;
};
inline J operator+(const J& a, const J& b) {
  return {a.v + b.v, a.g0 + b.g0, a.g1 + b.g1, a.h00 + b.h00, a.h01 + b.h01, a.h11 + b.h11};
}
inline J operator*(double c, const J& a) { return {c * a.v, c * a.g0, c * a.g1, c * a.h00, c * a.h01, c * a.h11}; }
inline J operator*(const J& a, const J& b) {
  return {a.v * b.v,
          a.g0 * b.v + a.v * b.g0,
          a.g1 * b.v + a.v * b.g1,
          a.h00 * b.v + 2 * a.g0 * b.g0 + a.v * b.h00,
          a.h01 * b.v + a.g0 * b.g1 + a.g1 * b.g0 + a.v * b.h01,
          a.h11 * b.v + 2 * a.g1 * b.g1 + a.v * b.h11};
}
// f(a) from f, f', f'' at a's value.
inline J apply(const J& a, double f, double d1, double d2) {
  return {f,
          d1 * a.g0,
          d1 * a.g1,
          d1 * a.h00 + d2 * a.g0 * a.g0,
          d1 * a.h01 + d2 * a.g0 * a.g1,
          d1 * a.h11 + d2 * a.g1 * a.g1};
}
inline J minus_sin(const J& a) {
  const double s = std::sin(a.v), c = std::cos(a.v);
  return apply(a, -s, -c, s);
}
inline J cos(const J& a) {
  const double s = std::sin(a.v), c = std::cos(a.v);
  return apply(a, c, -s, -c);
}

struct Shot {
  J S, B;  // the action and the end offset q^n - (q0 + eta)
};

// The propagation of (q^0, v^0) = (q0 + eta, w0) by two rk4 steps of h/2 through Simpson's nodes.
Shot shoot(double q0, double w0, double h) {
  const J origin{q0, 1, 0, 0, 0, 0};
  J d, v{w0, 0, 1, 0, 0, 0};
  const auto L = [&](const J& offset, const J& velocity) { return 0.5 * velocity * velocity + cos(origin + offset); };
  const auto acceleration = [&](const J& offset) { return minus_sin(origin + offset); };
  const auto rk4 = [&](double k) {
    const J a1 = acceleration(d);
    const J d2 = d + (0.5 * k) * v, v2 = v + (0.5 * k) * a1;
    const J a2 = acceleration(d2);
    const J d3 = d + (0.5 * k) * v2, v3 = v + (0.5 * k) * a2;
    const J a3 = acceleration(d3);
    const J d4 = d + k * v3, v4 = v + k * a3;
    const J a4 = acceleration(d4);
    d = d + (k / 6) * (v + 2.0 * v2 + 2.0 * v3 + v4);
    v = v + (k / 6) * (a1 + 2.0 * a2 + 2.0 * a3 + a4);
  };
  J S = (h / 6) * L(d, v);
  rk4(0.5 * h);
  S = S + (4 * h / 6) * L(d, v);
  rk4(0.5 * h);
  S = S + (h / 6) * L(d, v);
  return {S, d};
}

struct State {
  double q, p;
};

// One step from (q0, p0), w0 starting at `w`; returns the Newton iterations.
int step(State& s, double& w, double h) {
  constexpr double tolerance = 1e-14;
  for (int k = 1; k <= 50; ++k) {
    const Shot shot = shoot(s.q, w, h);
    const J& S = shot.S;
    const J& B = shot.B;
    const double Bw = B.g1, Be = B.g0;
    const double lambda = S.g1 / Bw;
    const double change = S.g0 - Be * lambda;      // D1 + D2: the momentum change
    const double residual = change - lambda + s.p;  // p0 + D1
    const double phi_ew = S.h01 - lambda * B.h01;
    const double phi_ww = S.h11 - lambda * B.h11;
    const double dlambda = phi_ww / Bw;
    const double jacobian = phi_ew - (1.0 + Be) * dlambda;
    const double update = residual / jacobian;
    w -= update;
    if (std::abs(update) <= tolerance * (1.0 + std::abs(w))) {
      const double offset = B.v - Bw * update;
      const double momentum_change = change - (jacobian + dlambda) * update;
      s.q += offset;
      s.p += momentum_change - (residual - jacobian * update);
      return k;
    }
  }
  throw std::runtime_error("SVIRK4 by hand: Newton did not converge");
}

HandRun run(long steps) {
  const double h = kT / static_cast<double>(steps);
  State s{kQ0, 0.0};
  double corrections[3] = {0, 0, 0};
  long iterations = 0;
  for (long i = 0; i < steps; ++i) {
    const double guess = s.p;  // M = 1
    double w = guess;
    if (i >= 3) w += 3 * corrections[0] - 3 * corrections[1] + corrections[2];
    else if (i == 2) w += 2 * corrections[0] - corrections[1];
    else if (i == 1) w += corrections[0];
    iterations += step(s, w, h);
    corrections[2] = corrections[1];
    corrections[1] = corrections[0];
    corrections[0] = w - guess;
  }
  return {s.q, s.p, 0.0, static_cast<double>(iterations) / static_cast<double>(steps)};
}

}  // namespace

HandRun svirk4_by_hand(long steps) {
  HandRun result;
  const double seconds = fastest([&] { return seconds_of([&] { result = run(steps); }); });
  result.seconds = seconds;
  return result;
}

}  // namespace varia::bench
