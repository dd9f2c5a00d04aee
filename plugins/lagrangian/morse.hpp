// The Morse bond between two points of the plane, V(r) = D (1 - exp(-a (r - r0)))^2 with
// r = |x1 - x0|: depth D, range a (an inverse length), rest length r0. Written once for any scalar:
// the morse-chain plugin sums it term by term (morse_chain.cpp), and the SDK's tests sum it in one
// dense model of the same chain.
#pragma once

#include <cmath>

namespace varia::plugins {

struct MorseBond {
  double depth = 1.0, range = 1.0, rest_length = 1.0;

  template <class T>
  T operator()(const T& x0, const T& y0, const T& x1, const T& y1) const {
    using std::exp;
    using std::sqrt;
    const T dx = x1 - x0, dy = y1 - y0;
    const T stretch = 1.0 - exp(-range * (sqrt(dx * dx + dy * dy) - rest_length));
    return depth * stretch * stretch;
  }
};

}  // namespace varia::plugins
