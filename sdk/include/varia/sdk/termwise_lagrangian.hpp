// A Lagrangian written as a sum of small terms, L(q, v) = sum_t f_t(z_{I_t}) with z = (q, v): each
// term a function of the few numbers of z that its index set I_t names, written once and templated
// on its scalar (as Ceres writes a residual block and differentiates it with fixed-size Jets). Each
// term is differentiated by forward mode at its own fixed size K (dual.hpp: FixedDual<K> for the
// gradient, FixedDual2<K> for the Hessian), so that an evaluation costs time linear in the number
// of terms and allocates nothing, whatever the size of the system; and the Hessian is sparse, its
// pattern the union of the terms' K x K blocks (hessian_pattern), which the Galerkin construction's
// sparse Newton solve and the inverse Legendre transform use.
//
//   struct Bond {                       // a term over K = 4 numbers: two points of the plane
//     double k;
//     template <class T>
//     T operator()(const varia::sdk::TermVec<T, 4>& x) const { ... }
//   };
//   class Chain final : public varia::sdk::TermwiseLagrangian {
//    public:
//     Chain(...) : TermwiseLagrangian(n, n) {
//       for (int i = 0; i + 3 < n; i += 2)
//         add_term(Bond{1.0}, {position(i), position(i + 1), position(i + 2), position(i + 3)});
//     }
//   };
//
// A term is any callable templated on the scalar that returns the scalar T: a struct with a
// template operator() as above, or a lambda []<class T>(const TermVec<T, K>& x) -> T { ... }.
// Not `auto`: Eigen's dual numbers return expression templates that refer to temporaries of the
// term's body, which would dangle (the SDK refuses such a term at compile time). add_term keeps a
// copy of the term. docs/writing-plugins.md has a worked 60-DOF example
// (plugins/lagrangian/morse_chain.cpp).
// Where every term is of the form 1/2 v^T M v - V(q) with M constant (read off each term's
// expression, velocity_structure.hpp: a sum of such terms is one), the Lagrangian has a constant mass
// matrix without declaring it (has_constant_mass_matrix, constant_mass_matrix: M is the Hessian's
// vv block, the same at every point), and the constructions' explicit forms serve it.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "varia/abi/lagrangian.hpp"
#include "varia/abi/sparse_pattern.hpp"
#include "varia/sdk/dual.hpp"
#include "varia/sdk/plugin.hpp"
#include "varia/sdk/velocity_structure.hpp"

namespace varia::sdk {

// The K numbers a term takes.
template <class T, int K>
using TermVec = Eigen::Matrix<T, K, 1>;

class TermwiseLagrangian : public Lagrangian {
 public:
  TermwiseLagrangian(int position_size, int velocity_size)
      : m_(position_size), n_(velocity_size), z_(position_size + velocity_size),
        z_jets_(position_size + velocity_size) {}
  int position_size() const noexcept final { return m_; }
  int velocity_size() const noexcept final { return n_; }

  Status evaluate(const double* q, const double* v, double* value, double* gradient,
                  double* hessian) noexcept final {
    return guarded(error_, [&] {
      gather(q, v, z_.data());
      double L = 0.0;
      if (gradient != nullptr) std::fill(gradient, gradient + m_ + n_, 0.0);
      if (hessian != nullptr) std::fill(hessian, hessian + pattern_.size(), 0.0);
      for (const auto& group : groups_) {
        if (hessian != nullptr) group->hessian(z_.data(), L, gradient, hessian);
        else if (gradient != nullptr) group->gradient(z_.data(), L, gradient);
        else group->value(z_.data(), L);
      }
      if (value != nullptr) *value = L;
    });
  }
  int hessian_pattern(const int** rows, const int** cols) const noexcept final {
    return pattern_.entries(rows, cols);
  }

  // Read off the terms (a model may still override both, to give M itself or to refuse the
  // explicit forms; the conformance suite checks a declared M against the Hessian).
  bool has_constant_mass_matrix() const noexcept override {
    if (!constant_mass_form_)
      constant_mass_form_ = std::all_of(groups_.begin(), groups_.end(),
                                        [&](const auto& group) { return group->constant_mass_form(m_); });
    return *constant_mass_form_;
  }
  bool constant_mass_matrix(double* mass) const noexcept override {
    if (!has_constant_mass_matrix()) return false;
    std::vector<double> q(m_, 0.5), v(n_, 0.0), hessian(pattern_.size());
    // evaluate() keeps no state between calls but the workspace it overwrites.
    if (const_cast<TermwiseLagrangian*>(this)->evaluate(q.data(), v.data(), nullptr, nullptr, hessian.data()) != nullptr)
      return false;
    std::fill(mass, mass + n_ * n_, 0.0);
    const int *rows = nullptr, *cols = nullptr;
    const int entries = pattern_.entries(&rows, &cols);
    for (int e = 0; e < entries; ++e)
      if (rows[e] >= m_ && cols[e] >= m_) {
        if (!std::isfinite(hessian[e])) return false;
        mass[(cols[e] - m_) * n_ + rows[e] - m_] = hessian[e];
      }
    return true;
  }

  bool evaluates_at_jets() const noexcept final { return true; }
  Status gradient_jet(const Jet2* q, const Jet2* v, Jet2* value, Jet2* gradient) noexcept final {
    return guarded(error_, [&] {
      gather(q, v, z_jets_.data());
      Jet2 L(0.0);
      std::fill(gradient, gradient + m_ + n_, Jet2(0.0));
      for (const auto& group : groups_) group->gradient_jet(z_jets_.data(), L, gradient);
      if (value != nullptr) *value = L;
    });
  }

 protected:
  // The index in z = (q, v) of q_i and of v_i; throws std::invalid_argument (a refused
  // parameter: exit 2 with the Lagrangian's JSON pointer) when there is no such number.
  int position(int i) const {
    checked(i, m_, "position");
    return i;
  }
  int velocity(int i) const {
    checked(i, n_, "velocity");
    return m_ + i;
  }

  // Adds the term f(z_{indices}) to L; the indices are positions in z (position(), velocity()).
  template <class Term, int K>
  void add_term(const Term& term, const int (&indices)[K]) {
    std::array<int, K> at;
    std::array<int, K * K> slots;
    for (int i = 0; i < K; ++i) {
      if (indices[i] < 0 || indices[i] >= m_ + n_)
        throw std::invalid_argument("term " + std::to_string(terms_) + ": index " + std::to_string(indices[i]) +
                                    " is not in (q, v), which has " + std::to_string(m_ + n_) + " numbers");
      at[i] = indices[i];
    }
    for (int j = 0; j < K; ++j)
      for (int i = 0; i < K; ++i) slots[j * K + i] = pattern_.slot(at[i], at[j]);
    group<Term, K>().add(term, at, slots);
    ++terms_;
    constant_mass_form_.reset();
  }

  std::string error_;  // the message of the last failed call (see guarded)

 private:
  // The terms of one type and arity, evaluated by one virtual call per group.
  struct Group {
    virtual ~Group() = default;
    virtual const void* key() const = 0;
    virtual void value(const double* z, double& L) const = 0;
    virtual void gradient(const double* z, double& L, double* gradient) const = 0;
    virtual void hessian(const double* z, double& L, double* gradient, double* hessian) const = 0;
    virtual void gradient_jet(const Jet2* z, Jet2& L, Jet2* gradient) const = 0;
    // Whether every term is 1/2 v^T M v - V(q) with M constant (z's first m numbers are q).
    virtual bool constant_mass_form(int m) const = 0;
  };
  template <class Term, int K>
  class Terms final : public Group {
   public:
    static const void* tag() {
      static const char unique = 0;
      return &unique;
    }
    const void* key() const override { return tag(); }
    void add(const Term& term, const std::array<int, K>& indices, const std::array<int, K * K>& slots) {
      terms_.push_back(term);
      indices_.push_back(indices);
      slots_.push_back(slots);
    }
    void value(const double* z, double& L) const override {
      TermVec<double, K> x;
      for (std::size_t t = 0; t < terms_.size(); ++t) {
        for (int i = 0; i < K; ++i) x(i) = z[indices_[t][i]];
        L += call(t, x);
      }
    }
    void gradient(const double* z, double& L, double* gradient) const override {
      first_order<FixedDual<K>>(z, L, gradient);
    }
    void hessian(const double* z, double& L, double* gradient, double* hessian) const override {
      TermVec<FixedDual2<K>, K> x;
      for (std::size_t t = 0; t < terms_.size(); ++t) {
        for (int i = 0; i < K; ++i) seed(x(i), z[indices_[t][i]], K, i, K, i);
        const FixedDual2<K> r = call(t, x);
        L += r.value().value();
        if (gradient != nullptr)
          for (int i = 0; i < K; ++i) gradient[indices_[t][i]] += derivative(r.value(), i);
        for (int j = 0; j < K; ++j)
          for (int i = 0; i < K; ++i) hessian[slots_[t][j * K + i]] += second_derivative(r, j, i);
      }
    }
    void gradient_jet(const Jet2* z, Jet2& L, Jet2* gradient) const override {
      first_order<JetDual<K>>(z, L, gradient);
    }
    bool constant_mass_form(int m) const override {
      for (std::size_t t = 0; t < terms_.size(); ++t) {
        TermVec<VelocityStructure, K> x;
        for (int i = 0; i < K; ++i)
          x(i) = indices_[t][i] < m ? VelocityStructure::position(0.5) : VelocityStructure::velocity(0.5);
        if (!constant_mass_form_of([&] { return call(t, x); })) return false;
      }
      return true;
    }

   private:
    // L and its gradient at doubles (D = FixedDual<K>) or at jets (D = JetDual<K>).
    template <class D, class X>
    void first_order(const X* z, X& L, X* gradient) const {
      TermVec<D, K> x;
      for (std::size_t t = 0; t < terms_.size(); ++t) {
        for (int i = 0; i < K; ++i) seed(x(i), z[indices_[t][i]], K, i);
        const D r = call(t, x);
        L += r.value();
        for (int i = 0; i < K; ++i) gradient[indices_[t][i]] += derivative(r, i);
      }
    }
    // Term t at x, whose result must be the scalar itself (see the note on `auto` above).
    template <class T>
    T call(std::size_t t, const TermVec<T, K>& x) const {
      static_assert(std::is_same_v<decltype(terms_[t](x)), T>,
                    "a term must return its scalar type T (declare it: -> T), not an expression (auto)");
      return terms_[t](x);
    }

    std::vector<Term> terms_;
    std::vector<std::array<int, K>> indices_;
    std::vector<std::array<int, K * K>> slots_;  // column-major: entry (i, j) at j K + i
  };

  // The group of terms of this type and arity, made at the first such term.
  template <class Term, int K>
  Terms<Term, K>& group() {
    for (const auto& g : groups_)
      if (g->key() == Terms<Term, K>::tag()) return static_cast<Terms<Term, K>&>(*g);
    groups_.push_back(std::make_unique<Terms<Term, K>>());
    return static_cast<Terms<Term, K>&>(*groups_.back());
  }
  static void checked(int i, int size, const char* what) {
    if (i < 0 || i >= size)
      throw std::invalid_argument("a term names " + std::string(what) + " " + std::to_string(i) + " of " +
                                  std::to_string(size));
  }
  // z = (q, v).
  template <class T>
  void gather(const T* q, const T* v, T* z) const {
    std::copy(q, q + m_, z);
    std::copy(v, v + n_, z + m_);
  }

  int m_, n_;
  int terms_ = 0;
  mutable std::optional<bool> constant_mass_form_;
  SparsePattern pattern_;
  std::vector<std::unique_ptr<Group>> groups_;
  std::vector<double> z_;  // workspace, sized once
  std::vector<Jet2> z_jets_;
};

}  // namespace varia::sdk
