// The Galerkin step's equations as a NewtonSolver system (galerkin.cpp's newton, and the
// constrained equations of galerkin_constrained.cpp, which border them). Private to core/src.
#pragma once

#include <algorithm>

#include "varia/core/galerkin.hpp"

namespace varia {

// The equations dS/dq^nu (+ f_d^nu when forced) = 0, nu in [first_equation, first_equation +
// blocks), in the control points [first_unknown, first_unknown + blocks), with p0 (if not null)
// added to the equation nu = 0 (IDEL: p0 + D1 L_d + f_d^0 = 0), as a system for NewtonSolver
// (solve/newton.hpp), with the exact Jacobian.
struct GalerkinDiscreteLagrangian::Equations {
  GalerkinDiscreteLagrangian& g;
  double h;
  int first_unknown, first_equation, blocks;
  const double* p0;
  bool forced;

  int size() const { return blocks * g.n_; }
  // F's round-off yardstick: the largest of its terms p0 and dS/dq^nu.
  double evaluate(Eigen::Ref<Eigen::VectorXd> F) {
    g.action(h, Order::hessian, forced);
    F = g.gradient_.segment(first_equation * g.n_, size());
    double yardstick = g.gradient_.lpNorm<Eigen::Infinity>();
    if (p0 != nullptr) {
      const Eigen::Map<const Eigen::VectorXd> momentum(p0, g.n_);
      F.head(g.n_) += momentum;
      yardstick = std::max(yardstick, momentum.lpNorm<Eigen::Infinity>());
    }
    return yardstick;
  }
  void factorize() {
    if (g.lagrangian_.sparse()) return g.factorize_sparse();
    g.dense_.jacobian = g.hessian_.block(first_equation * g.n_, first_unknown * g.n_, size(), size());
    g.dense_.factorize();
  }
  void solve(const Eigen::VectorXd& F, Eigen::VectorXd& update) {
    if (g.lagrangian_.sparse()) update = g.sparse_.lu.solve(F);
    else g.dense_.solve(F, update);
  }
  // x's round-off yardstick: the control points' size, q^0 + offsets.
  double apply(Eigen::Ref<const Eigen::VectorXd> update) {
    g.points_.middleCols(first_unknown, blocks).reshaped() -= update;
    return g.origin_.lpNorm<Eigen::Infinity>() + g.points_.lpNorm<Eigen::Infinity>();
  }
  // The gradient at the updated points; for the step's equations (p0 given), impulse_ less their
  // residuals there (see take_step).
  void finish(Eigen::Ref<const Eigen::VectorXd> update) {
    g.gradient_after_update(h, first_unknown, update, forced);
    if (p0 == nullptr) return;
    g.impulse_ -= g.gradient_.head(g.n_) + Eigen::Map<const Eigen::VectorXd>(p0, g.n_);
    for (int nu = 1; nu < g.s_; ++nu) g.impulse_ -= g.gradient_.segment(nu * g.n_, g.n_);
  }
};

}  // namespace varia
