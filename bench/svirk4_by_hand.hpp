// SVIRK4 written by hand for the pendulum of support.hpp (L = v^2/2 + cos q): the floor that
// issue #19's SVIRK4 row is measured against. The same mathematics as varia's shooting
// construction with rk4 and Simpson's rule (shooting.hpp: one shot, the state propagated as
// second-order jets in x = (eta, w0), exact Newton on w0 until p0 = -D1 L_d, the warm start from
// the last three corrections), but at a fixed size with everything inlined: jets of exactly two
// variables with a symmetric Hessian (6 numbers), the field -sin q and the integrand written in
// closed form, no plugin, no virtual call. What no generic code can beat with this method: a benchmark peer of our own,
// not a part of varia.
#pragma once

namespace varia::bench {

struct HandRun {
  double q = 0.0, p = 0.0, seconds = 0.0, newton_mean = 0.0;
};

// `steps` steps of h = kT / steps from (kQ0, 0); seconds are the fastest of repeated runs
// (support.hpp: fastest).
HandRun svirk4_by_hand(long steps);

}  // namespace varia::bench
