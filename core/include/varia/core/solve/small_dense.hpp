// Repeated solves with one small dense matrix A: for n <= 4 Eigen's closed-form inverse of a
// fixed-size matrix (cofactors: no pivot search, no blocking), so that a solve is a product of a
// few flops; above, Eigen's PartialPivLU. Eigen's PartialPivLU of a dynamic matrix pays its
// blocking and dispatch at every size, and a solve with a matrix right-hand side packs it as for
// a large product, which dominates a small system's step (bench/README.md). A singular A gives
// non-finite solutions in either case; the callers' solves check their residuals. Arguments whose size is fixed at compile time take
// fixed-size code (the shooting step at n <= 4, shooting.cpp).
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>

namespace varia {

class SmallDenseSolver {
 public:
  SmallDenseSolver() = default;
  explicit SmallDenseSolver(int n) : n_(n), inverse_(n, n), lu_(n) {}

  // A of a size fixed at compile time (n <= 4) takes the fixed-size path without a dispatch.
  template <class Matrix>
  void compute(const Matrix& A) {
    constexpr int N = Matrix::RowsAtCompileTime;
    if constexpr (N != Eigen::Dynamic && N <= 4) {
      fixed<N>() = Eigen::Matrix<double, N, N>(A).inverse();
    } else {
      switch (n_) {
        case 1: inverse_(0, 0) = 1.0 / A(0, 0); return;
        case 2: inverse_ = Eigen::Matrix2d(A).inverse(); return;
        case 3: inverse_ = Eigen::Matrix3d(A).inverse(); return;
        case 4: inverse_ = Eigen::Matrix4d(A).inverse(); return;
        default: lu_.compute(A);
      }
    }
  }
  // x = A^{-1} b, b a vector or a matrix (x distinct from b, of b's size). For n <= 4 a fixed-size
  // product where b's row count is fixed at compile time, else plain loops: Eigen's product of
  // dynamic matrices chooses its kernel at run time, which costs more than these few flops.
  template <class Rhs, class Result>
  void solve(const Rhs& b, Result& x) const {
    constexpr int N = Rhs::RowsAtCompileTime;
    if constexpr (N != Eigen::Dynamic && N <= 4) {
      x.noalias() = fixed<N>() * b;
    } else if (n_ > 4) {
      x.noalias() = lu_.solve(b);
    } else {
      for (Eigen::Index c = 0; c < b.cols(); ++c)
        for (int r = 0; r < n_; ++r) {
          double sum = 0.0;
          for (int k = 0; k < n_; ++k) sum += inverse_(r, k) * b(k, c);
          x(r, c) = sum;
        }
    }
  }

 private:
  template <int N>
  Eigen::Map<Eigen::Matrix<double, N, N>> fixed() {
    return Eigen::Map<Eigen::Matrix<double, N, N>>(inverse_.data());
  }
  template <int N>
  Eigen::Map<const Eigen::Matrix<double, N, N>> fixed() const {
    return Eigen::Map<const Eigen::Matrix<double, N, N>>(inverse_.data());
  }

  int n_ = 0;
  Eigen::MatrixXd inverse_;
  Eigen::PartialPivLU<Eigen::MatrixXd> lu_;
};

}  // namespace varia
