#include "varia/core/lie_group_field.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <type_traits>

namespace varia {

namespace {

LagrangianEvaluator& checked(const Manifold& manifold, LagrangianEvaluator& lagrangian) {
  if (manifold.structure() != ManifoldStructure::lie_group)
    throw std::invalid_argument(std::string("the Euler-Poincare field is for a Lie group, and the manifold is a ") +
                                structure_name(manifold.structure()));
  if (lagrangian.position_size() != manifold.point_size() || lagrangian.velocity_size() != manifold.dim())
    throw std::invalid_argument("the Lagrangian's sizes (" + std::to_string(lagrangian.position_size()) + " + " +
                                std::to_string(lagrangian.velocity_size()) + ") do not match the manifold's (" +
                                std::to_string(manifold.point_size()) + " + " + std::to_string(manifold.dim()) + ")");
  return lagrangian;
}

}  // namespace

LieGroupField::LieGroupField(Manifold& manifold, LagrangianEvaluator& lagrangian)
    : EulerLagrangeField(checked(manifold, lagrangian)),
      manifold_(manifold),
      m_(manifold.point_size()),
      generators_(m_ * n_),
      gradient_(m_ + n_),
      point_jet_(m_),
      generators_jet_(m_ * n_),
      gradient_jet_(m_ + n_),
      momentum_jet_(n_),
      torque_jet_(n_),
      y_jet_(m_ + n_),
      f_jet_(m_ + n_),
      momentum_(n_),
      torque_(n_),
      group_velocity_(m_),
      group_velocity_jet_(m_),
      velocity_hessian_jet_(0, 0),
      inertia_solve_(0) {
  if (constant_mass_) return;
  hessian_jet_variables_ = lagrangian.plugin().hessian_jet_variables();
  if (hessian_jet_variables_ < 2)
    throw std::invalid_argument(
        "one-step methods and the shooting construction on a Lie group need a Lagrangian with a constant inertia "
        "(L = 1/2 xi^T J xi - V(g)) or its Hessian at jets of at least 2 variables (Lagrangian::hessian_jet: the "
        "Euler-Poincare equations with an inertia that depends on the point); this one gives neither");
  const int k = m_ + n_;
  hessian_.resize(k, k);
  velocity_hessian_jet_ = VelocityHessianJet(m_, n_);
  inertia_solve_ = JetLinearSolve(n_);
}

int LieGroupField::jet_variables() const {
  return constant_mass_ ? kMaxJetVariables : std::min(kMaxJetVariables, hessian_jet_variables_);
}

std::vector<double> structure_constants(Manifold& manifold, const double* point) {
  const int n = manifold.dim(), V = 2 * n;
  const std::vector<double> zero(n, 0.0);
  std::vector<double> hessian(static_cast<std::size_t>(n) * V * V), structure(static_cast<std::size_t>(n) * n * n);
  check(manifold, manifold.chart(point, zero.data(), zero.data(), {}, {nullptr, nullptr, hessian.data()}),
        "manifold chart");
  for (int c = 0; c < n; ++c)
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b)
        structure[(static_cast<std::size_t>(c) * n + a) * n + b] =
            -2.0 * hessian[(static_cast<std::size_t>(c) * V + a) * V + n + b];
  return structure;
}

Eigen::MatrixXd coadjoint(const std::vector<double>& structure, const Eigen::Ref<const Eigen::MatrixXd>& directions,
                          const Eigen::Ref<const Eigen::VectorXd>& v) {
  const auto n = v.size();
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(n, directions.cols());
  for (Eigen::Index j = 0; j < directions.cols(); ++j)
    for (Eigen::Index b = 0; b < n; ++b)
      for (Eigen::Index c = 0; c < n; ++c)
        for (Eigen::Index a = 0; a < n; ++a)
          out(b, j) += v[c] * directions(a, j) * structure[static_cast<std::size_t>((c * n + a) * n + b)];
  return out;
}

void LieGroupField::learn_structure(const double* point) {
  if (structure_.empty()) structure_ = structure_constants(manifold_, point);
}

void LieGroupField::prepare(const double* y) {
  learn_structure(y);
  for (int k = 0; k < m_; ++k) point_jet_[k] = Jet2(y[k]);
  check(manifold_, manifold_.generators(point_jet_.data(), generators_jet_.data()), "manifold generators");
  for (int i = 0; i < m_ * n_; ++i) generators_[i] = generators_jet_[i].value;
  if (constant_mass_) lagrangian_.gradient(y, y + m_, gradient_.data());
  else lagrangian_.hessian(y, y + m_, gradient_.data(), hessian_.data());
}

void LieGroupField::prepare(const Jet2* y) {
  if (structure_.empty()) {  // once, on the first evaluation
    std::vector<double> point(m_);
    for (int k = 0; k < m_; ++k) point[k] = y[k].value;
    learn_structure(point.data());
  }
  check(manifold_, manifold_.generators(y, generators_jet_.data()), "manifold generators");
  lagrangian_.gradient_jet(y, y + m_, nullptr, gradient_jet_.data());
  if (constant_mass_) return;
  group_velocity_of(generators_jet_.data(), y + m_, group_velocity_jet_.data());  // the direction of L_xig g'
  velocity_hessian_jet_.evaluate(lagrangian_, y, y + m_, group_velocity_jet_.data());
}

template <class T>
void LieGroupField::group_velocity_of(const T* D, const T* xi, T* velocity) const {
  for (int k = 0; k < m_; ++k) {
    T sum(0.0);
    for (int a = 0; a < n_; ++a) sum += D[k * n_ + a] * xi[a];
    velocity[k] = sum;
  }
}

// g' = D xi;  L_xixi xi' = ad*_xi mu + D^T dL/dg - L_xig g', with (ad*_xi mu)_b =
// sum_{a,c} mu_c xi_a [e_a, e_b]_c and mu = dL/dxi (J xi for a constant inertia, where L_xig = 0).
template <class T>
void LieGroupField::rates(const T* y, const T* D, const T* gradient, T* velocity, T* rate) {
  T* mu;
  T* torque;
  const T* xi = y + m_;
  // g' = D xi: at doubles for L_xig g' (into `velocity` when asked for); at jets prepare() formed it
  // for L_xig g' with a configuration-dependent inertia, and it is only written out.
  [[maybe_unused]] double* group_velocity = nullptr;
  if constexpr (std::is_same_v<T, double>) {
    mu = momentum_.data();
    torque = torque_.data();
    group_velocity = velocity != nullptr ? velocity : group_velocity_.data();
    if (velocity != nullptr || !constant_mass_) group_velocity_of(D, xi, group_velocity);
  } else {
    mu = momentum_jet_.data();
    torque = torque_jet_.data();
    if (velocity != nullptr && constant_mass_) group_velocity_of(D, xi, velocity);
    else if (velocity != nullptr) std::copy(group_velocity_jet_.begin(), group_velocity_jet_.end(), velocity);
  }
  for (int c = 0; c < n_; ++c) {
    if (!constant_mass_) {
      mu[c] = gradient[m_ + c];
      continue;
    }
    T sum(0.0);
    for (int b = 0; b < n_; ++b)
      if (mass_(c, b) != 0.0) sum += mass_(c, b) * xi[b];
    mu[c] = sum;
  }
  for (int b = 0; b < n_; ++b) {
    T sum(0.0);
    for (int k = 0; k < m_; ++k) sum += D[k * n_ + b] * gradient[k];
    for (int c = 0; c < n_; ++c)
      for (int a = 0; a < n_; ++a) {
        const double C = structure_[(c * n_ + a) * n_ + b];
        if (C != 0.0) sum += C * (mu[c] * xi[a]);
      }
    if (!constant_mass_) {
      if constexpr (std::is_same_v<T, double>)
        for (int k = 0; k < m_; ++k) sum -= mixed(b, k) * group_velocity[k];
      else
        sum -= velocity_hessian_jet_.along(b);
    }
    torque[b] = sum;
  }
  solve_inertia(torque, rate);
}

void LieGroupField::solve_inertia(const double* torque, double* rate) {
  if (constant_mass_) return inverse_mass(torque, rate);
  inertia_lu_.compute(hessian_.bottomRightCorner(n_, n_));
  Eigen::Map<Eigen::VectorXd>(rate, n_) = inertia_lu_.solve(Eigen::Map<const Eigen::VectorXd>(torque, n_));
}

// At jets: L_xixi from the velocity rows of L's Hessian at jets (JetLinearSolve).
void LieGroupField::solve_inertia(const Jet2* torque, Jet2* rate) {
  if (constant_mass_) return inverse_mass(torque, rate);
  inertia_solve_.solve(velocity_hessian_jet_.inertia(), n_, torque, rate);
}

Status LieGroupField::eval(const double* y, double* f) noexcept {
  return guard([&] {
    prepare(y);
    rates(y, generators_.data(), gradient_.data(), f, f + m_);
  });
}

Status LieGroupField::eval(const Jet2* y, Jet2* f) noexcept {
  return guard([&] {
    prepare(y);
    rates(y, generators_jet_.data(), gradient_jet_.data(), f, f + m_);
  });
}

Status LieGroupField::algebra(const double* y, double* xi) noexcept {
  return guard([&] {
    std::copy(y + m_, y + m_ + n_, xi);
    prepare(y);
    rates(y, generators_.data(), gradient_.data(), static_cast<double*>(nullptr), xi + n_);
  });
}

Status LieGroupField::algebra(const Jet2* y, Jet2* xi) noexcept {
  return guard([&] {
    std::copy(y + m_, y + m_ + n_, xi);
    prepare(y);
    rates(y, generators_jet_.data(), gradient_jet_.data(), static_cast<Jet2*>(nullptr), xi + n_);
  });
}

Status LieGroupField::move(const double* y, const double* xi, double* moved) noexcept {
  return guard([&] {
    check(manifold_, manifold_.retract(y, xi, moved), "manifold chart");
    for (int a = 0; a < n_; ++a) moved[m_ + a] = y[m_ + a] + xi[n_ + a];
  });
}

Status LieGroupField::move(const Jet2* y, const Jet2* xi, Jet2* moved) noexcept {
  return guard([&] {
    check(manifold_, manifold_.translate(y, xi, moved), "manifold translate");
    for (int a = 0; a < n_; ++a) moved[m_ + a] = y[m_ + a] + xi[n_ + a];
  });
}

// Column c of df/dy is the derivative of f in y_c: the field at jets in a block of at most
// jet_variables() of the state's numbers at a time.
Status LieGroupField::jacobian(const double* y, double* f, double* df) noexcept {
  return guard([&] {
    const int N = m_ + n_, block = jet_variables();
    for (int first = 0; first < N; first += block) {
      const int count = std::min(block, N - first);
      for (int i = 0; i < N; ++i)
        y_jet_[i] = i >= first && i < first + count ? Jet2::variable(y[i], count, i - first) : Jet2(y[i]);
      prepare(y_jet_.data());
      rates(y_jet_.data(), generators_jet_.data(), gradient_jet_.data(), f_jet_.data(), f_jet_.data() + m_);
      for (int r = 0; r < N; ++r) {
        f[r] = f_jet_[r].value;
        for (int c = 0; c < count; ++c)
          df[(first + c) * N + r] = f_jet_[r].constant() ? 0.0 : f_jet_[r].gradient(c);
      }
    }
  });
}

}  // namespace varia
