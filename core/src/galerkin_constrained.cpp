// The Galerkin construction with holonomic constraints (galerkin.hpp, the top; docs/constraints.md):
// the step's equations bordered by the multipliers' blocks, as one Newton system, and the
// projection of p1 onto the constraint's cotangent space.
#include <cmath>

#include "galerkin_equations.hpp"
#include "varia/core/galerkin.hpp"

namespace varia {

// Equations nu in [first_equation, first_equation + blocks) (index e = nu - first_equation) and
// control points mu in [first_unknown, first_unknown + blocks) (index u), and the multipliers
// lambda_e (column e of multipliers_):
//   F_e = (the unconstrained equation e) - G(q^nu)^T lambda_e,   C_u = g(q^mu),
// with the Jacobian [A - H_e, -G(q^nu)^T; G(q^mu), 0], A the unconstrained one, H_e the Hessian of
// lambda_e . g at q^nu where q^nu is an unknown.
struct GalerkinDiscreteLagrangian::ConstrainedEquations {
  Equations base;

  GalerkinDiscreteLagrangian& g() { return base.g; }
  int positions() const { return base.size(); }
  int size() const { return base.size() + base.blocks * base.g.constraints_->size(); }

  double evaluate(Eigen::Ref<Eigen::VectorXd> F) {
    double yardstick = base.evaluate(F.head(positions()));
    auto& matrix = g().bordered_.matrix;
    matrix.zero();
    fill_unconstrained();
    const int first = std::min(base.first_equation, base.first_unknown);
    const int last = std::max(base.first_equation, base.first_unknown) + base.blocks;
    for (int nu = first; nu < last; ++nu) yardstick = std::max(yardstick, add_point(nu, F));
    return yardstick;
  }
  void factorize() { g().bordered_.matrix.factorize("the constrained Galerkin equations' Jacobian"); }
  void solve(const Eigen::VectorXd& F, Eigen::VectorXd& update) { g().bordered_.matrix.solve(F, update); }
  double apply(const Eigen::VectorXd& update) {
    const int m = g().constraints_->size();
    g().multipliers_.leftCols(base.blocks).reshaped() -= update.tail(base.blocks * m);
    return base.apply(update.head(positions()));
  }
  void finish(const Eigen::VectorXd& update) { base.finish(update.head(positions())); }

 private:
  // A's values: the dense Hessian's block, or the sparse Jacobian's values in their order.
  void fill_unconstrained() {
    auto& b = g().bordered_;
    if (g().lagrangian_.sparse()) {
      const double* values = g().sparse_.matrix.valuePtr();
      for (std::size_t k = 0; k < b.base.size(); ++k) b.matrix.at(b.base[k]) = values[k];
      return;
    }
    const int N = positions(), n = g().n_;
    const auto A = g().hessian_.block(base.first_equation * n, base.first_unknown * n, N, N);
    for (int c = 0, k = 0; c < N; ++c)
      for (int r = 0; r < N; ++r) b.matrix.at(b.base[k++]) = A(r, c);
  }
  // Control point nu's terms: its multiplier's in its equation, its constraint's row. Returns
  // |G^T lambda| for F's yardstick.
  double add_point(int nu, Eigen::Ref<Eigen::VectorXd> F) {
    auto& G = *g().constraints_;
    auto& b = g().bordered_;
    const int n = g().n_, m = G.size(), e = nu - base.first_equation, u = nu - base.first_unknown;
    const bool equation = e >= 0 && e < base.blocks, unknown = u >= 0 && u < base.blocks;
    g().q_ = g().origin_ + g().points_.col(nu);
    G.evaluate_jacobian(g().q_.data(), unknown ? F.data() + positions() + u * m : nullptr);
    const double* jacobian = G.jacobian().valuePtr();
    double size = 0.0;
    if (unknown)
      for (std::size_t k = 0; k < b.jacobian[u].size(); ++k) b.matrix.at(b.jacobian[u][k]) = jacobian[k];
    if (!equation) return size;
    const auto lambda = g().multipliers_.col(e);
    g().momentum_.noalias() = G.jacobian().transpose() * lambda;
    F.segment(e * n, n) -= g().momentum_;
    size = g().momentum_.lpNorm<Eigen::Infinity>();
    for (std::size_t k = 0; k < b.transposed[e].size(); ++k) b.matrix.at(b.transposed[e][k]) = -jacobian[k];
    if (!unknown) return size;
    G.evaluate_hessian(g().q_.data(), lambda.data());
    const double* hessian = G.hessian().valuePtr();
    for (std::size_t k = 0; k < b.hessian[e].size(); ++k) b.matrix.at(b.hessian[e][k]) -= hessian[k];
    return size;
  }
};

// The bordered Jacobian's pattern: A's entries (all of the dense block, or the sparse Jacobian's in
// its storage order), then per equation block e the Hessian's entries (where its point is an
// unknown) and -G^T in the columns of lambda_e, per unknown block u G in the rows of C_u.
void GalerkinDiscreteLagrangian::prepare_bordered(int first_unknown, int first_equation, int blocks) {
  Bordered& b = bordered_;
  if (b.matrix.ready() && b.first_unknown == first_unknown && b.first_equation == first_equation && b.blocks == blocks)
    return;
  b.first_unknown = first_unknown;
  b.first_equation = first_equation;
  b.blocks = blocks;
  for (auto* slots : {&b.hessian, &b.transposed, &b.jacobian}) slots->clear();
  b.base.clear();
  const int n = n_, m = constraints_->size(), N = blocks * n;
  b.matrix.reset(N + blocks * m);
  if (lagrangian_.sparse()) {
    const auto& A = sparse_.matrix;
    for (int c = 0; c < A.outerSize(); ++c)
      for (Eigen::SparseMatrix<double>::InnerIterator it(A, c); it; ++it)
        b.base.push_back(b.matrix.slot(static_cast<int>(it.row()), static_cast<int>(it.col())));
  } else {
    for (int c = 0; c < N; ++c)
      for (int r = 0; r < N; ++r) b.base.push_back(b.matrix.slot(r, c));
  }
  const auto& G = constraints_->jacobian();
  const auto& H = constraints_->hessian();
  b.hessian.resize(blocks);
  b.transposed.resize(blocks);
  b.jacobian.resize(blocks);
  for (int k = 0; k < blocks; ++k) {
    const int e = k, u = first_equation + k - first_unknown;  // equation k's point, as an unknown
    for (int row = 0; row < m; ++row)
      for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(G, row); it; ++it) {
        b.transposed[e].push_back(b.matrix.slot(e * n + static_cast<int>(it.col()), N + e * m + row));
        b.jacobian[k].push_back(b.matrix.slot(N + k * m + row, k * n + static_cast<int>(it.col())));
      }
    if (u < 0 || u >= blocks) continue;
    for (int c = 0; c < H.outerSize(); ++c)
      for (Eigen::SparseMatrix<double>::InnerIterator it(H, c); it; ++it)
        b.hessian[e].push_back(b.matrix.slot(e * n + static_cast<int>(it.row()), u * n + static_cast<int>(it.col())));
  }
  b.matrix.finish();
}

// Newton's method with the exact Jacobian on the bordered equations (solve/newton.hpp).
void GalerkinDiscreteLagrangian::constrained_newton(double h, int first_unknown, int first_equation, int blocks,
                                                    const double* p0, bool forced) {
  prepare_bordered(first_unknown, first_equation, blocks);
  ConstrainedEquations equations{Equations{*this, h, first_unknown, first_equation, blocks, p0, forced}};
  require_converged(solver_.solve(equations, statistics_), "the constrained Galerkin equations");
}

// p1 = p0 + impulse_ onto the constraint's cotangent space at q1 = q0 + (q^s - q^0): impulse_ gains
// -G(q1)^T mu (CotangentProjection).
void GalerkinDiscreteLagrangian::project_momentum(const double* p0) {
  q_ = origin_ + points_.col(s_);
  if (projection_ == nullptr) projection_ = std::make_unique<CotangentProjection>(*constraints_, constant_mass_entries(lagrangian_, q_.data()));
  v_ = Eigen::Map<const Eigen::VectorXd>(p0, n_) + impulse_;  // (workspace: the momentum to project)
  projection_->correction(q_.data(), v_.data(), momentum_.data());
  impulse_ += momentum_;
}

}  // namespace varia
