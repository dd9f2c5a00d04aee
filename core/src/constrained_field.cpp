#include "varia/core/constrained_field.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <type_traits>

namespace varia {

namespace {

// r = 0 (a constant jet at jets).
template <class T>
void set_zero(T& r) {
  r = T(0.0);
}

// The loops over G^T (n x m) and W (n x m) of the field, the projections and their jets.
// S = A^T B (m x m).
template <class Matrix>
void cross_product(const Matrix& A, const Matrix& B, Matrix& S) {
  for (Eigen::Index i = 0; i < S.rows(); ++i)
    for (Eigen::Index l = 0; l < S.cols(); ++l) {
      auto& s = S(i, l);
      set_zero(s);
      for (Eigen::Index j = 0; j < A.rows(); ++j) s += A(j, i) * B(j, l);
    }
}

// out += A^T x (m numbers).
template <class Matrix, class T, class Vector>
void add_transposed_product(const Matrix& A, const T* x, Vector& out) {
  for (Eigen::Index i = 0; i < A.cols(); ++i)
    for (Eigen::Index j = 0; j < A.rows(); ++j) out[i] += A(j, i) * x[j];
}

// x -= A y (n numbers).
template <class Matrix, class Vector, class T>
void subtract_product(const Matrix& A, const Vector& y, T* x) {
  for (Eigen::Index j = 0; j < A.rows(); ++j)
    for (Eigen::Index i = 0; i < A.cols(); ++i) x[j] -= A(j, i) * y[i];
}

}  // namespace

ConstrainedField::ConstrainedField(LagrangianEvaluator& lagrangian, HolonomicConstraints& constraints)
    : EulerLagrangeField(lagrangian),
      constraints_(constraints),
      m_(constraints.size()),
      quadratic_(constraints.quadratic()),
      has_jacobian_(constraints.gives_curvature_derivative()),
      point_(n_),
      values_(m_),
      unit_(Eigen::VectorXd::Zero(m_)),
      lu_(m_),
      jet_solve_(m_),
      lagrangian_hessian_(2 * n_, 2 * n_),
      free_jacobian_(n_, 2 * n_),
      R_(m_, 2 * n_),
      K_(n_, n_),
      weighted_(n_),
      product_(n_),
      scratch_(n_) {
  if (!constant_mass_)
    throw ConstraintsRefused("constraints need a Lagrangian with a constant mass matrix");
  const auto size = [&](auto& w) {
    for (auto* v : {&w.g, &w.curvature, &w.rhs, &w.multiplier, &w.step}) v->resize(m_);
    for (auto* v : {&w.gradient}) v->resize(2 * n_);
    for (auto* v : {&w.free, &w.offset, &w.start}) v->resize(n_);
    for (auto* M : {&w.GT, &w.W, &w.W_start}) M->resize(n_, m_);
    w.S.resize(m_, m_);
  };
  size(doubles_);
  size(jets_);
}

template <>
ConstrainedField::Workspace<double>& ConstrainedField::workspace<double>() {
  return doubles_;
}
template <>
ConstrainedField::Workspace<Jet2>& ConstrainedField::workspace<Jet2>() {
  return jets_;
}

void ConstrainedField::require_quadratic() const {
  if (!quadratic_)
    throw ConstraintsRefused("the constrained field at jets takes quadratic constraints only (Constraint::quadratic: "
                                "a constant Hessian); others would need g's third and fourth derivatives");
}

// At doubles g, G and H_i come from the constraints at q. At a jet q = p + d (p its value) they are
// g_i(p) + G_i(p) d + d^T H_i d / 2, G_i(p) + H_i d and H_i, exact for quadratic constraints.
template <class T>
void ConstrainedField::linearize(const T* q, const T* v, Workspace<T>& w) {
  constexpr bool jets = std::is_same_v<T, Jet2>;
  for (int k = 0; k < n_; ++k) point_[k] = value_of(q[k]);
  if constexpr (jets) {
    constraints_.evaluate_jacobian(point_.data(), values_.data());
    for (int i = 0; i < m_; ++i) w.g[i] = values_[i];
  } else {
    constraints_.evaluate_jacobian(point_.data(), w.g.data());
  }
  for (Eigen::Index i = 0; i < w.GT.size(); ++i) set_zero(w.GT.data()[i]);
  const auto& G = constraints_.jacobian();
  for (int i = 0; i < m_; ++i)
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(G, i); it; ++it) w.GT(it.col(), i) = it.value();
  if (!jets && v == nullptr) return;
  if constexpr (jets) {
    for (int k = 0; k < n_; ++k) {
      w.offset[k] = q[k];
      w.offset[k].value = 0.0;
    }
    for (int i = 0; i < m_; ++i)
      for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(G, i); it; ++it)
        add_scaled(w.g[i], it.value(), w.offset[it.col()]);
  }
  for (int i = 0; i < m_; ++i) {
    unit_[i] = 1.0;
    constraints_.evaluate_hessian(point_.data(), unit_.data());
    unit_[i] = 0.0;
    const auto& H = constraints_.hessian();
    if (v != nullptr) set_zero(w.curvature[i]);
    for (int k = 0; k < n_; ++k)
      for (Eigen::SparseMatrix<double>::InnerIterator it(H, k); it; ++it) {
        const int j = static_cast<int>(it.row());
        if (v != nullptr) w.curvature[i] += it.value() * v[j] * v[k];
        if constexpr (jets) {
          add_scaled(w.GT(j, i), it.value(), w.offset[k]);
          w.g[i] += (0.5 * it.value()) * w.offset[j] * w.offset[k];
        }
      }
  }
}

template <class T>
void ConstrainedField::factor(Workspace<T>& w) {
  for (int i = 0; i < m_; ++i)
    for (int j = 0; j < n_; ++j) {
      T& x = w.W(j, i);
      set_zero(x);
      for (int k = 0; k < n_; ++k)
        if (inverse_mass_(j, k) != 0.0) add_scaled(x, inverse_mass_(j, k), w.GT(k, i));
    }
  cross_product(w.GT, w.W, w.S);
}

template <class T>
void ConstrainedField::solve(const typename Workspace<T>::Matrix& A, const typename Workspace<T>::Vector& b,
                             typename Workspace<T>::Vector& x) {
  if constexpr (std::is_same_v<T, Jet2>) {
    jet_solve_.solve(A.data(), m_, b.data(), x.data());
  } else {
    lu_.compute(A);
    x = lu_.solve(b);
    if (!x.allFinite())
      throw NumericalFailure("G M^-1 G^T is singular: the constraints' Jacobian has lost its rank", std::nan(""));
  }
}

// f = (v, a), a = M^-1 L_q - W lambda with S lambda = G M^-1 L_q + c.
template <class T>
Status ConstrainedField::evaluate(const T* y, T* f) noexcept {
  return guard([&] {
    Workspace<T>& w = workspace<T>();
    const T* v = y + n_;
    std::copy_n(v, n_, f);
    if constexpr (std::is_same_v<T, Jet2>) lagrangian_.gradient_jet(y, v, nullptr, w.gradient.data());
    else lagrangian_.gradient(y, v, w.gradient.data());
    inverse_mass(w.gradient.data(), w.free.data());
    linearize(y, v, w);
    factor(w);
    w.rhs = w.curvature;
    add_transposed_product(w.GT, w.free.data(), w.rhs);
    solve<T>(w.S, w.rhs, w.multiplier);
    T* a = f + n_;
    std::copy_n(w.free.data(), n_, a);
    subtract_product(w.W, w.multiplier, a);
  });
}

Status ConstrainedField::eval(const double* y, double* f) noexcept { return evaluate(y, f); }

Status ConstrainedField::eval(const Jet2* y, Jet2* f) noexcept {
  if (!quadratic_) return "the constrained field at jets takes quadratic constraints only (Constraint::quadratic)";
  return evaluate(y, f);
}

// The derivative of a = u - W lambda in z = (q, v), u = M^-1 L_q (dG_i/dq = H_i): with r = W lambda,
// H_lambda = sum_i lambda_i H_i and C = dc/dq (Constraint::curvature_derivative, zero for quadratic
// constraints),
//   S dlambda = R dz,  R = G du + [((H_i (u - r))^T + C_i, 2 (H_i v)^T)]_i - [G M^-1 H_lambda, 0],
//   da = du - [M^-1 H_lambda, 0] dz - W dlambda.
Status ConstrainedField::jacobian(const double* y, double* f, double* df) noexcept {
  if (!has_jacobian_)
    return "the constrained field (index 1) has a Jacobian where the constraints give the derivative of v^T H_i(q) v "
           "in q (Constraint::curvature_derivative) only: its multiplier's derivatives need them";
  if (Status status = evaluate(y, f)) return status;
  return guard([&] {
    Workspace<double>& w = doubles_;
    const Eigen::Map<const Eigen::VectorXd> v(y + n_, n_);
    lagrangian_.hessian(y, y + n_, w.gradient.data(), lagrangian_hessian_.data());
    free_jacobian_.noalias() = inverse_mass_ * lagrangian_hessian_.topRows(n_);
    weighted_.noalias() = w.W * w.multiplier;
    R_.noalias() = w.GT.transpose() * free_jacobian_;
    product_ = w.free - weighted_;
    for (int i = 0; i < m_; ++i) {
      unit_[i] = 1.0;
      constraints_.evaluate_hessian(y, unit_.data());
      unit_[i] = 0.0;
      scratch_.noalias() = constraints_.hessian() * product_;
      R_.row(i).head(n_) += scratch_.transpose();
      scratch_.noalias() = constraints_.hessian() * v;
      R_.row(i).tail(n_) += 2.0 * scratch_.transpose();
    }
    if (!quadratic_) {
      constraints_.evaluate_curvature_derivative(y, y + n_);
      R_.leftCols(n_) += constraints_.curvature_derivative();
    }
    constraints_.evaluate_hessian(y, w.multiplier.data());
    K_.noalias() = inverse_mass_ * constraints_.hessian();
    R_.leftCols(n_).noalias() -= w.GT.transpose() * K_;
    Eigen::Map<Eigen::MatrixXd> J(df, 2 * n_, 2 * n_);
    J.setZero();
    J.topRightCorner(n_, n_).setIdentity();
    J.bottomRows(n_) = free_jacobian_;
    J.bottomLeftCorner(n_, n_) -= K_;
    for (int c = 0; c < 2 * n_; ++c) {  // lu_ holds S's factors from evaluate()
      w.rhs = lu_.solve(R_.col(c));
      J.col(c).tail(n_).noalias() -= w.W * w.rhs;
    }
  });
}

// q = q^ - W(q^) mu with g(q) = 0 by Newton's method in mu (Jacobian G(q) W(q^)); at jets two
// iterations past the values' convergence.
template <class T>
void ConstrainedField::project_point(T* q, const SolverOptions& options) {
  Workspace<T>& w = workspace<T>();
  linearize(q, static_cast<const T*>(nullptr), w);
  factor(w);
  w.W_start = w.W;
  for (int k = 0; k < n_; ++k) w.start[k] = q[k];
  for (int i = 0; i < m_; ++i) set_zero(w.multiplier[i]);
  int exact = std::is_same_v<T, Jet2> ? 2 : 0;  // iterations still to run after the values converged
  for (int iteration = 0;; ++iteration) {
    double residual = 0.0;
    for (int i = 0; i < m_; ++i) residual = std::max(residual, std::abs(value_of(w.g[i])));
    if (residual <= options.tolerance && exact-- == 0) return;
    if (iteration == options.max_iterations)
      throw NumericalFailure("the projection onto the constraint did not converge", residual);
    cross_product(w.GT, w.W_start, w.S);
    solve<T>(w.S, w.g, w.step);
    w.multiplier += w.step;
    std::copy_n(w.start.data(), n_, q);
    subtract_product(w.W_start, w.multiplier, q);
    linearize(q, static_cast<const T*>(nullptr), w);
  }
}

// v - W S^-1 G v, with the workspace's G^T at q.
template <class T>
void ConstrainedField::project_onto_hidden(T* v, Workspace<T>& w) {
  factor(w);
  for (int i = 0; i < m_; ++i) set_zero(w.rhs[i]);
  add_transposed_product(w.GT, v, w.rhs);
  solve<T>(w.S, w.rhs, w.multiplier);
  subtract_product(w.W, w.multiplier, v);
}

void ConstrainedField::project(double* q, double* v, const SolverOptions& options) {
  project_point(q, options);
  project_onto_hidden(v, doubles_);
}

void ConstrainedField::project(Jet2* q, Jet2* v, const SolverOptions& options) {
  require_quadratic();
  project_point(q, options);
  project_onto_hidden(v, jets_);
}

void ConstrainedField::project_velocity(const double* q, double* v) {
  linearize(q, static_cast<const double*>(nullptr), doubles_);
  project_onto_hidden(v, doubles_);
}

}  // namespace varia
