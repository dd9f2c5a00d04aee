// Compensated (Kahan) summation of a state's updates, the one implementation the constructions
// share (lie_verlet.cpp: R_{k+1} = R_k + R_k (F_k - I) and Pi; galerkin.cpp: q1 = q0 + (q^s - q^0)
// and p1 = p0 + (p1 - p0)).
#pragma once

#include <Eigen/Core>

namespace varia {

// s += increment, coefficient by coefficient, by Kahan's compensated summation (Higham, "Accuracy
// and Stability of Numerical Algorithms", 2nd ed., alg. 4.2) with the running compensation c
// (zero at the start of a run): the rounding error of each addition is kept in c and taken off
// the next increment, so that the error of a sum of N updates stays O(eps |s|) instead of growing
// like eps sqrt(N) |s|. s, increment and c have the same size and linear coefficient access
// (plain matrices and vectors, Maps, vector blocks); nothing is allocated.
template <class Sum, class Increment, class Carry>
void compensated_add(Sum&& s, const Increment& increment, Carry&& c) {
  for (Eigen::Index i = 0; i < s.size(); ++i) {
    const double y = increment.coeff(i) - c.coeff(i);
    const double t = s.coeff(i) + y;
    c.coeffRef(i) = (t - s.coeff(i)) - y;
    s.coeffRef(i) = t;
  }
}

}  // namespace varia
