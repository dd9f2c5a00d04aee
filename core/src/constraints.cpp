#include "varia/core/constraints.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>

#include <Eigen/LU>
#include <Eigen/SparseLU>

#include "varia/core/solve/newton.hpp"

namespace varia {

namespace {

// Sets a matrix's pattern from (row, col) entries (values 0) and returns where each entry's value
// lives in valuePtr().
template <class Matrix>
std::vector<int> pattern_positions(Matrix& matrix, const std::vector<std::pair<int, int>>& entries) {
  std::vector<Eigen::Triplet<double>> triplets;
  for (const auto& [row, col] : entries) triplets.emplace_back(row, col, 0.0);
  matrix.setFromTriplets(triplets.begin(), triplets.end());
  matrix.makeCompressed();
  std::vector<int> positions;
  for (const auto& [row, col] : entries) positions.push_back(static_cast<int>(&matrix.coeffRef(row, col) - matrix.valuePtr()));
  return positions;
}

void check_finite(const Constraint& constraint, const double* values, int count, const char* what) {
  for (int i = 0; i < count; ++i)
    if (!std::isfinite(values[i]))
      throw PluginFault(std::string("the constraint's ") + what + " is not finite", constraint.origin());
}

}  // namespace

HolonomicConstraints::HolonomicConstraints(std::vector<Constraint*> constraints, int n) : n_(n) {
  std::vector<std::pair<int, int>> jacobian_entries, hessian_entries;
  for (Constraint* constraint : constraints) {
    Part part{constraint, m_, {}, {}, {}, {}};
    const int *rows = nullptr, *cols = nullptr;
    const int jacobian_count = constraint->jacobian_pattern(&rows, &cols);
    for (int e = 0; e < jacobian_count; ++e) jacobian_entries.emplace_back(m_ + rows[e], cols[e]);
    const int hessian_count = constraint->hessian_pattern(&rows, &cols);
    for (int e = 0; e < hessian_count; ++e) hessian_entries.emplace_back(rows[e], cols[e]);
    part.jacobian_values.resize(jacobian_count);
    part.hessian_values.resize(hessian_count);
    m_ += constraint->size();
    parts_.push_back(std::move(part));
  }
  jacobian_.resize(m_, n_);
  hessian_.resize(n_, n_);
  const std::vector<int> jacobian_positions = pattern_positions(jacobian_, jacobian_entries);
  const std::vector<int> hessian_positions = pattern_positions(hessian_, hessian_entries);
  std::size_t j = 0, k = 0;
  for (Part& part : parts_) {
    for (Eigen::Index e = 0; e < part.jacobian_values.size(); ++e) part.jacobian_slots.push_back(jacobian_positions[j++]);
    for (Eigen::Index e = 0; e < part.hessian_values.size(); ++e) part.hessian_slots.push_back(hessian_positions[k++]);
  }
  g_.resize(m_);
  curvature_derivative_ = jacobian_;  // the same pattern and slots
}

bool HolonomicConstraints::quadratic() const {
  return std::all_of(parts_.begin(), parts_.end(), [](const Part& part) { return part.constraint->quadratic(); });
}

bool HolonomicConstraints::gives_curvature_derivative() const {
  return std::all_of(parts_.begin(), parts_.end(),
                     [](const Part& part) { return part.constraint->gives_curvature_derivative(); });
}

void HolonomicConstraints::values(const double* q, double* g) {
  for (Part& part : parts_) {
    check(*part.constraint, part.constraint->evaluate(q, g + part.first_row, nullptr), "constraint evaluate");
    check_finite(*part.constraint, g + part.first_row, part.constraint->size(), "value");
  }
}

// Each part's values in G's pattern from `call` (a Status, writing part.jacobian_values), checked
// and placed into `into` (G's pattern and slots).
template <class Call>
void HolonomicConstraints::gather(Eigen::SparseMatrix<double, Eigen::RowMajor>& into, const char* call,
                                  const char* what, Call&& values_of) {
  double* values = into.valuePtr();
  for (Part& part : parts_) {
    check(*part.constraint, values_of(part), call);
    check_finite(*part.constraint, part.jacobian_values.data(), static_cast<int>(part.jacobian_values.size()), what);
    for (std::size_t e = 0; e < part.jacobian_slots.size(); ++e) values[part.jacobian_slots[e]] = part.jacobian_values[e];
  }
}

void HolonomicConstraints::evaluate_jacobian(const double* q, double* g) {
  gather(jacobian_, "constraint evaluate", "Jacobian", [&](Part& part) {
    return part.constraint->evaluate(q, g == nullptr ? nullptr : g + part.first_row, part.jacobian_values.data());
  });
}

void HolonomicConstraints::evaluate_curvature_derivative(const double* q, const double* v) {
  gather(curvature_derivative_, "constraint curvature_derivative", "curvature derivative",
         [&](Part& part) { return part.constraint->curvature_derivative(q, v, part.jacobian_values.data()); });
}

void HolonomicConstraints::evaluate_hessian(const double* q, const double* lambda) {
  std::fill_n(hessian_.valuePtr(), hessian_.nonZeros(), 0.0);
  double* values = hessian_.valuePtr();
  for (Part& part : parts_) {
    check(*part.constraint, part.constraint->weighted_hessian(q, lambda + part.first_row, part.hessian_values.data()),
          "constraint weighted_hessian");
    check_finite(*part.constraint, part.hessian_values.data(), static_cast<int>(part.hessian_values.size()), "Hessian");
    for (std::size_t e = 0; e < part.hessian_slots.size(); ++e) values[part.hessian_slots[e]] += part.hessian_values[e];
  }
}

double HolonomicConstraints::residual(const double* q) {
  values(q, g_.data());
  return m_ == 0 ? 0.0 : g_.lpNorm<Eigen::Infinity>();
}

double HolonomicConstraints::velocity_residual(const double* q, const double* v) {
  evaluate_jacobian(q);
  g_.noalias() = jacobian_ * Eigen::Map<const Eigen::VectorXd>(v, n_);
  return m_ == 0 ? 0.0 : g_.lpNorm<Eigen::Infinity>();
}

TangentBasis::TangentBasis(HolonomicConstraints& constraints)
    : constraints_(constraints),
      normals_(constraints.dim(), constraints.size()),
      basis_(constraints.dim(), constraints.dim() - constraints.size()),
      qr_(constraints.dim(), constraints.size()),
      workspace_(constraints.dim()) {}

const Eigen::MatrixXd& TangentBasis::at(const double* q) {
  constraints_.evaluate_jacobian(q);
  normals_ = constraints_.jacobian().transpose();
  qr_.compute(normals_);
  basis_.setZero();
  basis_.bottomRows(basis_.cols()).setIdentity();
  qr_.householderQ().applyThisOnTheLeft(basis_, workspace_);
  return basis_;
}

// Below kDenseLimit rows the matrix is copied into a dense one, sized once, and factorized by
// partial pivoting in place: nothing is allocated, and for the small bordered systems of a pendulum
// or a short chain it is faster than SparseLU, whose numeric factorization and solve allocate their
// workspace at every call. Above it, SparseLU keeps the cost of a long chain linear in its length.
struct FixedPatternMatrix::Factorization {
  static constexpr int kDenseLimit = 32;
  bool dense = false;
  Eigen::MatrixXd dense_matrix;
  Eigen::PartialPivLU<Eigen::MatrixXd> dense_lu;
  Eigen::SparseLU<Eigen::SparseMatrix<double>> sparse_lu;
};

FixedPatternMatrix::FixedPatternMatrix() : lu_(std::make_unique<Factorization>()) {}
FixedPatternMatrix::~FixedPatternMatrix() = default;

void FixedPatternMatrix::solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& out) {
  if (lu_->dense) out = lu_->dense_lu.solve(rhs);
  else out = lu_->sparse_lu.solve(rhs);
}

void FixedPatternMatrix::reset(int size) {
  entries_.clear();
  positions_.clear();
  matrix_.resize(size, size);
  ready_ = analyzed_ = false;
}

int FixedPatternMatrix::slot(int row, int col) {
  entries_.emplace_back(row, col, 0.0);
  return static_cast<int>(entries_.size()) - 1;
}

void FixedPatternMatrix::finish() {
  matrix_.setFromTriplets(entries_.begin(), entries_.end());
  matrix_.makeCompressed();
  for (const auto& entry : entries_)
    positions_.push_back(static_cast<int>(&matrix_.coeffRef(entry.row(), entry.col()) - matrix_.valuePtr()));
  entries_.clear();
  entries_.shrink_to_fit();
  const int n = size();
  lu_->dense = n <= Factorization::kDenseLimit;
  if (lu_->dense) {
    lu_->dense_matrix = Eigen::MatrixXd::Zero(n, n);  // off the pattern it stays zero (the LU works on a copy)
    lu_->dense_lu = Eigen::PartialPivLU<Eigen::MatrixXd>(n);
  }
  ready_ = true;
}

void FixedPatternMatrix::factorize(const char* what) {
  if (lu_->dense) return factorize_dense(what);
  if (!analyzed_) {
    lu_->sparse_lu.analyzePattern(matrix_);
    analyzed_ = true;
  }
  lu_->sparse_lu.factorize(matrix_);
  if (lu_->sparse_lu.info() != Eigen::Success)
    throw NumericalFailure(std::string(what) + " is singular: " + lu_->sparse_lu.lastErrorMessage(), std::nan(""));
}

// Partial pivoting meets a zero pivot exactly where the matrix is singular in its arithmetic, as
// SparseLU reports it; a pivot that is not finite means the entries were not.
void FixedPatternMatrix::factorize_dense(const char* what) {
  auto& A = lu_->dense_matrix;
  for (int c = 0; c < matrix_.outerSize(); ++c)
    for (Eigen::SparseMatrix<double>::InnerIterator it(matrix_, c); it; ++it) A(it.row(), c) = it.value();
  lu_->dense_lu.compute(A);
  const auto pivots = lu_->dense_lu.matrixLU().diagonal();
  for (Eigen::Index i = 0; i < pivots.size(); ++i)
    if (!(std::isfinite(pivots(i)) && pivots(i) != 0.0))
      throw NumericalFailure(std::string(what) + " is singular: pivot " + std::to_string(i) + " is " +
                                 std::to_string(pivots(i)),
                             std::nan(""));
}

CotangentProjection::CotangentProjection(HolonomicConstraints& constraints,
                                         const std::vector<Eigen::Triplet<double>>& mass)
    : constraints_(constraints) {
  const int n = constraints.dim(), m = constraints.size();
  saddle_.reset(n + m);
  std::vector<std::pair<int, double>> mass_slots;
  for (const auto& entry : mass) mass_slots.emplace_back(saddle_.slot(entry.row(), entry.col()), entry.value());
  const auto& G = constraints.jacobian();
  for (int row = 0; row < m; ++row)
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(G, row); it; ++it) {
      transposed_slots_.push_back(saddle_.slot(static_cast<int>(it.col()), n + row));
      slots_.push_back(saddle_.slot(n + row, static_cast<int>(it.col())));
    }
  saddle_.finish();
  saddle_.zero();
  for (const auto& [slot, value] : mass_slots) saddle_.at(slot) += value;
  rhs_ = Eigen::VectorXd::Zero(n + m);
  velocity_.resize(n);
}

void CotangentProjection::correction(const double* q, const double* p, double* correction) {
  const int n = constraints_.dim();
  constraints_.evaluate_jacobian(q);
  const double* G = constraints_.jacobian().valuePtr();
  for (std::size_t e = 0; e < slots_.size(); ++e) saddle_.at(transposed_slots_[e]) = saddle_.at(slots_[e]) = G[e];
  saddle_.factorize("the projection onto the constraint's cotangent space ([M G^T; G 0])");
  rhs_.head(n) = Eigen::Map<const Eigen::VectorXd>(p, n);
  saddle_.solve(rhs_, solution_);
  velocity_ = solution_.head(n);
  Eigen::Map<Eigen::VectorXd> out(correction, n);
  out.setZero();  // (then -= in place: the negated product would be evaluated into a temporary)
  out.noalias() -= constraints_.jacobian().transpose() * solution_.tail(constraints_.size());
}

}  // namespace varia
