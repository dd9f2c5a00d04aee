// Fixed-size instances of code written once for any size: a construction's step at a small
// dimension n runs with Eigen's fixed-size vectors and matrices (loops of a known length, no
// dispatch on the size, nothing on the heap), chosen once when the construction is built; other
// sizes run the same code at Eigen::Dynamic. The constructions share the choice (galerkin.cpp,
// shooting.cpp).
#pragma once

#include <Eigen/Core>
#include <type_traits>

namespace varia {

// f(std::integral_constant<int, N>{}) with N = n for n <= 4, N = Eigen::Dynamic otherwise: the
// fixed-size instance of a member template, chosen once.
template <class F>
auto for_dimension(int n, F f) {
  switch (n) {
    case 1: return f(std::integral_constant<int, 1>{});
    case 2: return f(std::integral_constant<int, 2>{});
    case 3: return f(std::integral_constant<int, 3>{});
    case 4: return f(std::integral_constant<int, 4>{});
    default: return f(std::integral_constant<int, Eigen::Dynamic>{});
  }
}

// A size fixed at compile time, or the run-time one where it is Eigen::Dynamic.
template <int Fixed>
constexpr int fixed_or(int runtime) {
  return Fixed == Eigen::Dynamic ? runtime : Fixed;
}

// k N, or Eigen::Dynamic where N is.
template <int N>
constexpr int fixed_times(int k) {
  return N == Eigen::Dynamic ? Eigen::Dynamic : k * N;
}

}  // namespace varia
