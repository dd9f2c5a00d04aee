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
  if (entries > 0 && (rows == nullptr || cols == nullptr))
    throw PluginFault(where + "the effect declares a Hessian pattern without its rows and columns", effect->origin());
  for (int e = 0; e < entries; ++e) {
    // The pattern indexes the effect's own k coordinates; one outside them is the plugin's fault.
    if (rows[e] < 0 || rows[e] >= k || cols[e] < 0 || cols[e] >= k)
      throw PluginFault(where + "the effect's Hessian pattern names entry " + std::to_string(e) + " at (row " +
                            std::to_string(rows[e]) + ", column " + std::to_string(cols[e]) + "), outside its " +
                            std::to_string(k) + " coordinates",
                        effect->origin());
    term.slots.push_back(pattern_.slot(term.indices[rows[e]], term.indices[cols[e]]));
  }
  term.at_doubles.x.resize(k);
  term.at_doubles.gradient.resize(k);
  term.hessian.resize(entries);
  term.effect = std::move(effect);
  return term;
}

// L = 1/2 sum_j m_j v_j^2 - sum_e V_e and dL/dq = -sum_e dV_e/dq, dL/dv_j = m_j v_j, at doubles
// (with d2L/dv_j^2 = m_j, d2L/dq2 = -sum_e d2V_e/dq2 when hessian is not null) or at jets (the
// effects' gradient_jet; hessian null). Each term gathers its coordinates x_j = q[indices_j] and
// scatters -V, -dV/dx and -d2V/dx2 into L's value, dL/dq and Hessian slots.
template <class T>
void CompositeLagrangian::sum_terms(const T* q, const T* v, T* value, T* gradient, double* hessian) {
  if (value != nullptr) {
    *value = T(0.0);
    for (int j = 0; j < n_; ++j) *value += 0.5 * masses_[j] * v[j] * v[j];
  }
  if (gradient != nullptr)
    for (int j = 0; j < n_; ++j) {
      gradient[j] = T(0.0);
      gradient[n_ + j] = masses_[j] * v[j];
    }
  if (hessian != nullptr) {
    std::fill(hessian + n_, hessian + pattern_.size(), 0.0);
    std::copy(masses_.begin(), masses_.end(), hessian);
  }
  for (Term& term : terms_) {
    const std::size_t k = term.at_doubles.x.size();
    std::vector<T>& x = term.template buffers<T>().x;
    std::vector<T>& dV = term.template buffers<T>().gradient;
    x.resize(k);  // at jets: sized at the first evaluation, then a no-op
    dV.resize(k);
    for (std::size_t j = 0; j < k; ++j) x[j] = q[term.indices[j]];
    T V(0.0);
    Status status;
    if constexpr (std::is_same_v<T, double>)
      status = term.effect->evaluate(x.data(), value ? &V : nullptr, gradient ? dV.data() : nullptr,
                                     hessian ? term.hessian.data() : nullptr);
    else
      status = term.effect->gradient_jet(x.data(), value ? &V : nullptr, dV.data());
    if (status != nullptr) throw std::runtime_error(std::string("effect: ") + status);
    if (value != nullptr) *value -= V;
    if (gradient != nullptr)
      for (std::size_t j = 0; j < k; ++j) gradient[term.indices[j]] -= dV[j];
    if (hessian != nullptr)
      for (std::size_t e = 0; e < term.slots.size(); ++e) hessian[term.slots[e]] -= term.hessian[e];
  }
}

Status CompositeLagrangian::evaluate(const double* q, const double* v, double* value,
                                     double* gradient, double* hessian) noexcept {
  try {
    sum_terms(q, v, value, gradient, hessian);
    return nullptr;
  } catch (const std::exception& e) {
    error_ = e.what();
    return error_.c_str();
  }
}

bool CompositeLagrangian::evaluates_at_jets() const noexcept {
  return std::all_of(terms_.begin(), terms_.end(), [](const Term& term) { return term.effect->evaluates_at_jets(); });
}

Status CompositeLagrangian::gradient_jet(const Jet2* q, const Jet2* v, Jet2* value, Jet2* gradient) noexcept {
  try {
    sum_terms(q, v, value, gradient, nullptr);
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
