#include "varia/core/composite.hpp"

#include <algorithm>
#include <stdexcept>

namespace varia {

namespace {

std::vector<double> per_coordinate(const std::vector<double>& masses, int space_dim) {
  if (space_dim < 1) throw std::invalid_argument("space_dim: expected at least 1");
  if (masses.empty()) throw std::invalid_argument("masses: expected at least one mass");
  std::vector<double> result;
  for (double m : masses) {
    if (!(m > 0)) throw std::invalid_argument("masses: expected numbers > 0");
    result.insert(result.end(), space_dim, m);
  }
  return result;
}

}  // namespace

CompositeLagrangian::CompositeLagrangian(int space_dim, std::vector<double> masses,
                                         std::vector<std::shared_ptr<Effect>> effects)
    : d_(space_dim), masses_(per_coordinate(masses, space_dim)) {
  n_ = static_cast<int>(masses_.size());
  // The kinetic energy's Hessian: d2L/dv_j^2 = m_j, at slots 0 .. n-1.
  for (int j = 0; j < n_; ++j) pattern_.slot(n_ + j, n_ + j);
  for (std::size_t e = 0; e < effects.size(); ++e) terms_.push_back(bind(std::move(effects[e]), e));
}

CompositeLagrangian::Term CompositeLagrangian::bind(std::shared_ptr<Effect> effect, std::size_t index) {
  const int particles = n_ / d_;
  std::vector<double> masses(particles);
  for (int i = 0; i < particles; ++i) masses[i] = masses_[i * d_];
  const std::string where = "terms/" + std::to_string(index) + ": ";
  if (Status status = effect->bind(d_, particles, masses.data())) throw std::invalid_argument(where + status);
  Term term;
  const int k = effect->coordinates(&term.indices);
  for (int j = 0; j < k; ++j)
    if (term.indices[j] < 0 || term.indices[j] >= n_)
      throw std::invalid_argument(where + "the effect names a coordinate outside q");
  const int *rows = nullptr, *cols = nullptr;
  const int entries = effect->hessian_pattern(&rows, &cols);
  for (int e = 0; e < entries; ++e) term.slots.push_back(pattern_.slot(term.indices[rows[e]], term.indices[cols[e]]));
  term.x.resize(k);
  term.gradient.resize(k);
  term.hessian.resize(entries);
  term.effect = std::move(effect);
  return term;
}

// Gathers the term's coordinates x_j = q[indices_j], and scatters -V, -dV/dx and -d2V/dx2 into
// L's value, dL/dq and Hessian slots.
void CompositeLagrangian::add_term(Term& term, const double* q, double* value, double* gradient,
                                   double* hessian) {
  const int k = static_cast<int>(term.x.size());
  for (int j = 0; j < k; ++j) term.x[j] = q[term.indices[j]];
  double V = 0.0;
  if (Status status = term.effect->evaluate(term.x.data(), value ? &V : nullptr,
                                            gradient ? term.gradient.data() : nullptr,
                                            hessian ? term.hessian.data() : nullptr))
    throw std::runtime_error(std::string("effect: ") + status);
  if (value != nullptr) *value -= V;
  if (gradient != nullptr)
    for (int j = 0; j < k; ++j) gradient[term.indices[j]] -= term.gradient[j];
  if (hessian != nullptr)
    for (std::size_t e = 0; e < term.slots.size(); ++e) hessian[term.slots[e]] -= term.hessian[e];
}

// L = 1/2 sum_j m_j v_j^2 - sum_e V_e: dL/dq = -sum_e dV_e/dq, dL/dv_j = m_j v_j,
// d2L/dv_j^2 = m_j, d2L/dq2 = -sum_e d2V_e/dq2.
Status CompositeLagrangian::evaluate(const double* q, const double* v, double* value,
                                     double* gradient, double* hessian) noexcept {
  try {
    if (value != nullptr) {
      *value = 0.0;
      for (int j = 0; j < n_; ++j) *value += 0.5 * masses_[j] * v[j] * v[j];
    }
    if (gradient != nullptr) {
      std::fill(gradient, gradient + n_, 0.0);
      for (int j = 0; j < n_; ++j) gradient[n_ + j] = masses_[j] * v[j];
    }
    if (hessian != nullptr) {
      std::fill(hessian + n_, hessian + pattern_.size(), 0.0);
      std::copy(masses_.begin(), masses_.end(), hessian);
    }
    for (Term& term : terms_) add_term(term, q, value, gradient, hessian);
    return nullptr;
  } catch (const std::exception& e) {
    error_ = e.what();
    return error_.c_str();
  }
}

bool CompositeLagrangian::evaluates_at_jets() const noexcept {
  return std::all_of(terms_.begin(), terms_.end(), [](const Term& term) { return term.effect->evaluates_at_jets(); });
}

// The same sums at jets: dL/dq = -sum_e dV_e/dq at jets, dL/dv_j = m_j v_j.
Status CompositeLagrangian::gradient_jet(const Jet2* q, const Jet2* v, Jet2* value, Jet2* gradient) noexcept {
  try {
    if (value != nullptr) {
      *value = Jet2(0.0);
      for (int j = 0; j < n_; ++j) *value += (0.5 * masses_[j]) * (v[j] * v[j]);
    }
    for (int j = 0; j < n_; ++j) {
      gradient[j] = Jet2(0.0);
      gradient[n_ + j] = masses_[j] * v[j];
    }
    for (Term& term : terms_) {
      const std::size_t k = term.x.size();
      term.x_jets.resize(k);
      term.gradient_jets.resize(k);
      for (std::size_t j = 0; j < k; ++j) term.x_jets[j] = q[term.indices[j]];
      Jet2 V;
      if (Status status = term.effect->gradient_jet(term.x_jets.data(), value ? &V : nullptr, term.gradient_jets.data()))
        throw std::runtime_error(std::string("effect: ") + status);
      if (value != nullptr) *value -= V;
      for (std::size_t j = 0; j < k; ++j) gradient[term.indices[j]] -= term.gradient_jets[j];
    }
    return nullptr;
  } catch (const std::exception& e) {
    error_ = e.what();
    return error_.c_str();
  }
}

int CompositeLagrangian::hessian_pattern(const int** rows, const int** cols) const noexcept {
  return pattern_.entries(rows, cols);
}

bool CompositeLagrangian::constant_mass_matrix(double* mass) const noexcept {
  std::fill(mass, mass + static_cast<std::size_t>(n_) * n_, 0.0);
  for (int j = 0; j < n_; ++j) mass[static_cast<std::size_t>(j) * n_ + j] = masses_[j];
  return true;
}

}  // namespace varia
