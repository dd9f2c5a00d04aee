#include "varia/core/mechanics.hpp"

#include <Eigen/Cholesky>

#include <cmath>
#include <string>

#include "varia/core/explicit_shot.hpp"

namespace varia {

LagrangianEvaluator::LagrangianEvaluator(Lagrangian& lagrangian)
    : lagrangian_(lagrangian),
      m_(lagrangian.position_size()),
      n_(lagrangian.velocity_size()),
      gradient_(m_ + n_) {
  pattern_size_ = lagrangian_.hessian_pattern(&pattern_rows_, &pattern_cols_);
  if (pattern_size_ >= 0) {
    sparse_values_.resize(pattern_size_);
    velocity_block_.resize(n_, n_);
  } else {
    hessian_.resize(m_ + n_, m_ + n_);
    lu_ = Eigen::PartialPivLU<Eigen::MatrixXd>(n_);
    Eigen::MatrixXd mass(n_, n_);
    if (lagrangian_.constant_mass_matrix(mass.data())) {
      const Eigen::LLT<Eigen::MatrixXd> factor(mass);
      if (factor.info() == Eigen::Success) inverse_mass_ = factor.solve(Eigen::MatrixXd::Identity(n_, n_));
    }
  }
}

// Out of line, so that the inline check that runs on every evaluation is a loop of scalar loads
// and well-predicted branches.
void LagrangianEvaluator::not_finite(const char* what) const {
  throw NumericalFailure(std::string("the Lagrangian's ") + what + " is not finite", std::nan(""),
                         lagrangian_.origin());
}

double LagrangianEvaluator::value(const double* q, const double* v) {
  const double L = unchecked_value(q, v);
  check_finite(&L, 1, "value");
  return L;
}

double LagrangianEvaluator::unchecked_value(const double* q, const double* v) {
  double L = 0.0;
  check(lagrangian_, lagrangian_.evaluate(q, v, &L, nullptr, nullptr), "Lagrangian evaluation");
  ++counters_.lagrangian;
  return L;
}

double LagrangianEvaluator::value_and_gradient(const double* q, const double* v, double* gradient) {
  double L = 0.0;
  evaluate_gradient(q, v, &L, gradient);
  return L;
}

double LagrangianEvaluator::hessian(const double* q, const double* v, double* gradient,
                                    double* hessian) {
  const int k = m_ + n_;
  if (pattern_size_ >= 0) {
    const double L = sparse_hessian(q, v, gradient, sparse_values_.data());
    Eigen::Map<Eigen::MatrixXd> H(hessian, k, k);
    H.setZero();
    for (int e = 0; e < pattern_size_; ++e) H(pattern_rows_[e], pattern_cols_[e]) = sparse_values_[e];
    return L;
  }
  double L = 0.0;
  check(lagrangian_, lagrangian_.evaluate(q, v, &L, gradient, hessian), "Lagrangian Hessian");
  ++counters_.hessian;
  check_finite(gradient, k, "gradient");
  check_finite(hessian, k * k, "Hessian");
  return L;
}

double LagrangianEvaluator::sparse_hessian(const double* q, const double* v, double* gradient,
                                           double* values) {
  double L = 0.0;
  check(lagrangian_, lagrangian_.evaluate(q, v, &L, gradient, values), "Lagrangian Hessian");
  ++counters_.hessian;
  check_finite(gradient, m_ + n_, "gradient");
  check_finite(values, pattern_size_, "Hessian");
  return L;
}

void LagrangianEvaluator::gradient_jet(const Jet2* q, const Jet2* v, Jet2* value, Jet2* gradient) {
  check(lagrangian_, lagrangian_.gradient_jet(q, v, value, gradient), "Lagrangian gradient at jets");
  ++counters_.hessian;
  bool finite = value == nullptr || isfinite(*value);
  for (int i = 0; i < m_ + n_; ++i) finite = finite && isfinite(gradient[i]);
  if (!finite)
    throw NumericalFailure("the Lagrangian's gradient at jets is not finite", std::nan(""), lagrangian_.origin());
}

void LagrangianEvaluator::shoot(const ShotPlan& plan, const double* q0, const double* w0, double h, Jet2* action,
                                Jet2* offsets) {
  kernel::ExplicitShot shot{&plan, q0, w0, h, action, offsets};
  check(lagrangian_, lagrangian_.run(kernel::call(shot)), "Lagrangian shot");
  counters_.hessian += shot_evaluations(plan);
  bool finite = isfinite(*action);
  for (int r = 0; r < plan.n; ++r) finite = finite && isfinite(offsets[r]);
  if (!finite) throw NumericalFailure("the shot is not finite", std::nan(""), lagrangian_.origin());
}

bool LagrangianEvaluator::verlet_steps(double* q, double* d, double* f, const double* K, long steps) {
  kernel::StormerVerletSteps verlet{q, d, f, K, steps};
  check(lagrangian_, lagrangian_.run(kernel::call(verlet)), "Lagrangian Stormer-Verlet steps");
  counters_.gradient += steps;
  for (int i = 0; i < n_; ++i)
    if (!std::isfinite(q[i]) || !std::isfinite(d[i]) || !std::isfinite(f[i])) return false;
  return true;
}

void LagrangianEvaluator::hessian_product(const double* q, const double* v, const double* u, double* out) {
  const int k = m_ + n_;
  Eigen::Map<Eigen::VectorXd> product(out, k);
  const Eigen::Map<const Eigen::VectorXd> direction(u, k);
  if (lagrangian_.hessian_jet_variables() > 0) {
    if (product_.empty()) product_point_.resize(k), product_direction_.resize(k), product_.resize(k);
    for (int i = 0; i < k; ++i) {
      product_point_[i] = Jet2(i < m_ ? q[i] : v[i - m_]);
      product_direction_[i] = Jet2(u[i]);
    }
    hessian_jet(product_point_.data(), product_point_.data() + m_, 0, k, 1, product_direction_.data(), product_.data());
    for (int i = 0; i < k; ++i) out[i] = product_[i].value;
  } else if (pattern_size_ >= 0) {
    sparse_hessian(q, v, gradient_.data(), sparse_values_.data());
    product.setZero();
    for (int e = 0; e < pattern_size_; ++e) out[pattern_rows_[e]] += sparse_values_[e] * u[pattern_cols_[e]];
  } else {
    hessian(q, v, gradient_.data(), hessian_.data());
    product.noalias() = hessian_ * direction;
  }
}

void LagrangianEvaluator::hessian_jet(const Jet2* q, const Jet2* v, int first, int count, int directions,
                                      const Jet2* U, Jet2* out) {
  check(lagrangian_, lagrangian_.hessian_jet(q, v, first, count, directions, U, out), "Lagrangian Hessian at jets");
  ++counters_.hessian;
  for (int i = 0; i < count * directions; ++i)
    if (!isfinite(out[i]))
      throw NumericalFailure("the Lagrangian's Hessian at jets is not finite", std::nan(""), lagrangian_.origin());
}

void LagrangianEvaluator::legendre(const double* q, const double* v, double* p) {
  gradient(q, v, gradient_.data());
  Eigen::Map<Eigen::VectorXd>(p, n_) = gradient_.tail(n_);
}

// dL/dv (q, v) = p in v, as a system for NewtonSolver (solve/newton.hpp), with the exact
// Jacobian d2L/dv2; a sparse Lagrangian's velocity block is assembled from its pattern and
// factorized by sparse LU.
struct LagrangianEvaluator::InverseLegendre {
  LagrangianEvaluator& l;
  const double* q;
  const double* p;
  Eigen::Map<Eigen::VectorXd> v;

  int size() const { return l.n_; }
  // F's round-off yardstick: p, of the size of dL/dv.
  double evaluate(Eigen::Ref<Eigen::VectorXd> F) {
    const Eigen::Map<const Eigen::VectorXd> momentum(p, l.n_);
    if (l.pattern_size_ < 0) {
      l.hessian(q, v.data(), l.gradient_.data(), l.hessian_.data());
    } else {
      l.sparse_hessian(q, v.data(), l.gradient_.data(), l.sparse_values_.data());
      l.triplets_.clear();
      for (int e = 0; e < l.pattern_size_; ++e)
        if (l.pattern_rows_[e] >= l.m_ && l.pattern_cols_[e] >= l.m_)
          l.triplets_.emplace_back(l.pattern_rows_[e] - l.m_, l.pattern_cols_[e] - l.m_, l.sparse_values_[e]);
      l.velocity_block_.setFromTriplets(l.triplets_.begin(), l.triplets_.end());
    }
    F = l.gradient_.tail(l.n_) - momentum;
    return momentum.lpNorm<Eigen::Infinity>();
  }
  void factorize() {
    if (l.pattern_size_ < 0) l.lu_.compute(l.hessian_.bottomRightCorner(l.n_, l.n_));
    else l.sparse_lu_.compute(l.velocity_block_);
  }
  void solve(const Eigen::VectorXd& F, Eigen::VectorXd& update) {
    if (l.pattern_size_ < 0) update.noalias() = l.lu_.solve(F);
    else update = l.sparse_lu_.solve(F);
  }
  double apply(const Eigen::VectorXd& update) {
    v -= update;
    return v.lpNorm<Eigen::Infinity>();
  }
  void finish(const Eigen::VectorXd&) {}
};

// Newton's method on dL/dv (q, v) - p = 0; L is assumed hyperregular (paper, sec. 3
// "Implementation issues": the initial guess for shooting).
void LagrangianEvaluator::inverse_legendre(const double* q, const double* p, double* v,
                                           const SolverOptions& options) {
  if (inverse_mass_.size() > 0) {
    Eigen::Map<Eigen::VectorXd>(v, n_).noalias() = inverse_mass_ * Eigen::Map<const Eigen::VectorXd>(p, n_);
    return;
  }
  if (legendre_solver_.options().tolerance != options.tolerance ||
      legendre_solver_.options().max_iterations != options.max_iterations)
    legendre_solver_ = NewtonSolver(options);
  InverseLegendre equations{*this, q, p, Eigen::Map<Eigen::VectorXd>(v, n_)};
  require_converged(legendre_solver_.solve(equations), "the inverse Legendre transform's equations");
}

double LagrangianEvaluator::energy(const double* q, const double* v, const double* p) {
  return Eigen::Map<const Eigen::VectorXd>(p, n_).dot(Eigen::Map<const Eigen::VectorXd>(v, n_)) - unchecked_value(q, v);
}

double LagrangianEvaluator::energy(const double* q, const double* v) {
  const double L = value_and_gradient(q, v, gradient_.data());
  return gradient_.tail(n_).dot(Eigen::Map<const Eigen::VectorXd>(v, n_)) - L;
}

std::vector<Eigen::Triplet<double>> constant_mass_entries(LagrangianEvaluator& evaluator, const double* q) {
  const int m = evaluator.position_size(), n = evaluator.velocity_size();
  std::vector<Eigen::Triplet<double>> mass;
  if (evaluator.sparse()) {
    const Eigen::VectorXd v = Eigen::VectorXd::Zero(n);
    Eigen::VectorXd gradient(m + n), values(evaluator.pattern_size());
    evaluator.sparse_hessian(q, v.data(), gradient.data(), values.data());
    for (int e = 0; e < evaluator.pattern_size(); ++e)
      if (evaluator.pattern_rows()[e] >= m && evaluator.pattern_cols()[e] >= m)
        mass.emplace_back(evaluator.pattern_rows()[e] - m, evaluator.pattern_cols()[e] - m, values[e]);
    return mass;
  }
  Eigen::MatrixXd M(n, n);
  if (!evaluator.plugin().constant_mass_matrix(M.data()))
    throw std::invalid_argument("constraints need a Lagrangian with a constant mass matrix");
  for (int c = 0; c < n; ++c)
    for (int r = 0; r < n; ++r)
      if (M(r, c) != 0.0) mass.emplace_back(r, c, M(r, c));
  return mass;
}

}  // namespace varia
