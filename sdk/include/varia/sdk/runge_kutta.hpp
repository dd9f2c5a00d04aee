// Runge-Kutta one-step methods (Hairer, Lubich & Wanner, "Geometric Numerical Integration",
// sec. II.1) for the one_step plugin kind: a plugin gives its Butcher tableau, order and
// self-adjointness, and RungeKutta steps doubles and jets with one template. Implicit stages are
// solved by Newton's method with the vector field's exact Jacobian on the values; at jets, the
// implicit function theorem gives the derivatives of the stages (see correct_jets).
//
// Every Runge-Kutta method commutes with affine maps of the state, hence with the tangent lift of
// every linear or affine group action on R^n: the equivariance that makes shooting-based discrete
// Lagrangians G-invariant (paper, sec. 3 "Group-invariant shooting-based discrete Lagrangians").
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>
#include <cmath>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "varia/core/explicit_shot.hpp"
#include "varia/abi/one_step.hpp"
#include "varia/core/solve/newton.hpp"
#include "varia/sdk/plugin.hpp"

namespace varia::sdk {

// Y_i = y0 + h sum_j a_ij K_j, y1 = y0 + h sum_i b_i K_i, K_i = f(Y_i).
struct ButcherTableau {
  Eigen::MatrixXd a;
  Eigen::VectorXd b, c;
  int stages() const { return static_cast<int>(b.size()); }
  // Strictly lower triangular a: stage i needs stages j < i only.
  bool is_explicit() const {
    for (int i = 0; i < stages(); ++i)
      for (int j = i; j < stages(); ++j)
        if (a(i, j) != 0.0) return false;
    return true;
  }
};

// The classical fourth-order method (the paper's RK4, sec. 3 "Examples").
inline ButcherTableau classic_rk4() {
  ButcherTableau t{Eigen::MatrixXd::Zero(4, 4), Eigen::VectorXd(4), Eigen::VectorXd(4)};
  t.a(1, 0) = 0.5;
  t.a(2, 1) = 0.5;
  t.a(3, 2) = 1.0;
  t.b << 1.0 / 6, 1.0 / 3, 1.0 / 3, 1.0 / 6;
  t.c << 0.0, 0.5, 0.5, 1.0;
  return t;
}

// The explicit midpoint rule y1 = y0 + h f(y0 + h/2 f(y0)), order 2.
inline ButcherTableau explicit_midpoint() {
  ButcherTableau t{Eigen::MatrixXd::Zero(2, 2), Eigen::VectorXd(2), Eigen::VectorXd(2)};
  t.a(1, 0) = 0.5;
  t.b << 0.0, 1.0;
  t.c << 0.0, 0.5;
  return t;
}

// The collocation method with nodes c (Hairer-Lubich-Wanner, Thm. II.1.4): a_ij = int_0^{c_i}
// l_j, b_j = int_0^1 l_j for the Lagrange basis l_j through c, from the moment conditions
// sum_j a_ij c_j^k = c_i^{k+1}/(k+1), sum_j b_j c_j^k = 1/(k+1), k < s. Gauss nodes give the
// s-stage Gauss method (order 2s, self-adjoint); c = {1/2} the implicit midpoint rule.
inline ButcherTableau collocation_tableau(const std::vector<double>& nodes) {
  const int s = static_cast<int>(nodes.size());
  Eigen::MatrixXd powers(s, s), moments(s, s);
  Eigen::VectorXd unit_moments(s);
  for (int k = 0; k < s; ++k) {
    unit_moments(k) = 1.0 / (k + 1);
    for (int j = 0; j < s; ++j) {
      powers(j, k) = std::pow(nodes[j], k);
      moments(j, k) = std::pow(nodes[j], k + 1) / (k + 1);
    }
  }
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(powers.transpose());
  ButcherTableau t;
  t.a = lu.solve(moments.transpose()).transpose();
  t.b = lu.solve(unit_moments);
  t.c = Eigen::Map<const Eigen::VectorXd>(nodes.data(), s);
  return t;
}

class RungeKutta : public OneStepMethod {
 public:
  RungeKutta(ButcherTableau tableau, int order, bool self_adjoint)
      : t_(std::move(tableau)),
        explicit_(t_.is_explicit()),
        order_(order),
        self_adjoint_(self_adjoint) {}
  RungeKuttaTableau explicit_tableau() const noexcept final {
    return explicit_ ? view() : RungeKuttaTableau{};
  }
  int order() const noexcept final { return order_; }
  bool self_adjoint() const noexcept final { return self_adjoint_; }
  const char* equivariance() const noexcept final { return "affine"; }
  void set_solver(double tolerance, int max_iterations) noexcept final {
    newton_ = NewtonSolver(SolverOptions{tolerance, max_iterations});
  }
  Status step(VectorField& field, double h, const double* y0, double* y1,
              StageSolve* report) noexcept final {
    return guarded(error_, [&] { advance(field, h, y0, y1, *report); });
  }
  Status step(VectorField& field, double h, const Jet2* y0, Jet2* y1,
              StageSolve* report) noexcept final {
    return guarded(error_, [&] { advance(field, h, y0, y1, *report); });
  }

 private:
  template <class T>
  struct Workspace {
    std::vector<T> K, Y;  // stages K_i (s blocks of N), a stage point
  };

  template <class T>
  Workspace<T>& workspace(int N) {
    Workspace<T>* w;
    if constexpr (std::is_same_v<T, double>) w = &doubles_;
    else w = &jets_;
    w->K.resize(t_.stages() * N);
    w->Y.resize(N);
    return *w;
  }

  template <class T>
  static void eval(VectorField& field, const T* y, T* f) {
    if (Status status = field.eval(y, f)) throw std::runtime_error(status);
  }

  // The tableau as the core's recurrences take it (explicit_shot.hpp).
  RungeKuttaTableau view() const { return {t_.stages(), t_.a.data(), t_.b.data(), t_.c.data()}; }

  // Y = y0 + h sum_{j in [0, count)} a_ij K_j.
  template <class T>
  void stage_point(double h, int i, int count, int N, const T* y0, const std::vector<T>& K,
                   std::vector<T>& Y) const {
    runge_kutta_stage_point(view(), h, i, count, N, y0, K.data(), Y.data());
  }

  template <class T>
  void advance(VectorField& field, double h, const T* y0, T* y1, StageSolve& report) {
    const int N = field.size();
    Workspace<T>& w = workspace<T>(N);
    report = StageSolve{};
    if (explicit_) {
      explicit_runge_kutta_step(view(), h, N, y0, y1, w.K.data(), w.Y.data(),
                                [&](const T* y, T* f) { eval(field, y, f); });
      return;
    }
    implicit_stages(field, h, y0, report);
    runge_kutta_combination(view(), h, N, y0, w.K.data(), y1);
  }

  // The stage equations G_i(K) = K_i - f(Y_i) = 0 at doubles and their Newton matrix
  // dG/dK: blocks delta_ij I - h a_ij f'(Y_i), for the stages in doubles_.K.
  void assemble(VectorField& field, double h, const double* y0) {
    const int N = field.size(), s = t_.stages();
    auto& w = doubles_;
    residual_.resize(s * N);
    newton_matrix_.resize(s * N, s * N);
    df_.resize(N, N);
    for (int i = 0; i < s; ++i) {
      stage_point(h, i, s, N, y0, w.K, w.Y);
      if (Status status = field.jacobian(w.Y.data(), &residual_[i * N], df_.data()))
        throw std::runtime_error(status);
      for (int r = 0; r < N; ++r) residual_[i * N + r] = w.K[i * N + r] - residual_[i * N + r];
      for (int j = 0; j < s; ++j)
        newton_matrix_.block(i * N, j * N, N, N) = -h * t_.a(i, j) * df_;
    }
    newton_matrix_ += Eigen::MatrixXd::Identity(s * N, s * N);
  }

  // The stage equations G(K) = 0 at y0 as a system for varia's NewtonSolver (core/solve/
  // newton.hpp), with the exact Jacobian; the stages K in doubles_.K.
  struct StageEquations {
    RungeKutta& rk;
    VectorField& field;
    double h;
    const double* y0;

    int size() const { return static_cast<int>(rk.doubles_.K.size()); }
    Eigen::Map<Eigen::VectorXd> stages() { return {rk.doubles_.K.data(), size()}; }
    // G's round-off yardstick: the stages' size (G_i = K_i - f(Y_i)).
    double evaluate(Eigen::Ref<Eigen::VectorXd> G) {
      rk.assemble(field, h, y0);
      G = rk.residual_;
      return stages().lpNorm<Eigen::Infinity>();
    }
    void factorize() { rk.lu_.compute(rk.newton_matrix_); }
    void solve(const Eigen::VectorXd& G, Eigen::VectorXd& update) { update.noalias() = rk.lu_.solve(G); }
    double apply(const Eigen::VectorXd& update) {
      stages() -= update;
      return stages().lpNorm<Eigen::Infinity>();
    }
    void finish(const Eigen::VectorXd&) {}
  };

  // Newton's method on G(K) = 0 from K_i = f(y0), with the stopping rule of every solve of varia.
  void implicit_stages(VectorField& field, double h, const double* y0, StageSolve& report) {
    const int N = field.size(), s = t_.stages();
    auto& K = doubles_.K;
    eval(field, y0, K.data());
    for (int i = 1; i < s; ++i) std::copy(K.begin(), K.begin() + N, K.begin() + i * N);
    StageEquations equations{*this, field, h, y0};
    const SolveReport solve = newton_.solve(equations);
    report.iterations = solve.iterations;
    report.residual = solve.residual;
    if (solve.converged()) return;
    report.converged = false;
    if (solve.outcome == SolveReport::Outcome::non_finite)
      throw std::runtime_error("the implicit stage equations have a non-finite residual");
    throw std::runtime_error("the implicit stage equations did not converge in " +
                             std::to_string(solve.iterations) + " Newton iterations");
  }

  // At jets: the stage values by Newton's method on the values, then the implicit function
  // theorem for their derivatives: with the exact Newton matrix J at the solution, the
  // correction K <- K - J^{-1} G(K, y0) in jet arithmetic, started from the constant jets of the
  // values, makes the first derivatives exact, and a second correction the second derivatives
  // (each correction doubles the order of the jet that is exact). No iteration on jets.
  void implicit_stages(VectorField& field, double h, const Jet2* y0, StageSolve& report) {
    const int N = field.size(), s = t_.stages();
    std::vector<double>& values = value_point_;
    values.resize(N);
    for (int r = 0; r < N; ++r) values[r] = y0[r].value;
    workspace<double>(N);
    implicit_stages(field, h, values.data(), report);
    assemble(field, h, values.data());
    lu_.compute(newton_matrix_);
    auto& K = jets_.K;
    for (int e = 0; e < s * N; ++e) K[e] = Jet2(doubles_.K[e]);
    for (int correction = 0; correction < 2; ++correction) correct_jets(field, h, y0);
  }

  // K <- K - J^{-1} G(K, y0), one linear solve per jet component.
  void correct_jets(VectorField& field, double h, const Jet2* y0) {
    const int N = field.size(), s = t_.stages();
    auto& w = jets_;
    int variables = 0;
    for (int r = 0; r < N; ++r) variables = std::max<int>(variables, y0[r].gradient.size());
    const int components = 1 + variables + variables * variables;
    residual_jets_.resize(s * N);
    for (int i = 0; i < s; ++i) {
      stage_point(h, i, s, N, y0, w.K, w.Y);
      eval(field, w.Y.data(), &residual_jets_[i * N]);
    }
    components_.setZero(s * N, components);
    for (int e = 0; e < s * N; ++e) {
      const Jet2 g = w.K[e] - residual_jets_[e];
      components_(e, 0) = g.value;
      if (g.constant()) continue;
      components_.row(e).segment(1, variables) = g.gradient.transpose();
      components_.row(e).tail(variables * variables) = g.hessian.reshaped().transpose();
    }
    solution_ = lu_.solve(components_);
    for (int e = 0; e < s * N; ++e) {
      Jet2 update(solution_(e, 0));
      if (variables > 0) {
        update.gradient = solution_.row(e).segment(1, variables).transpose();
        update.hessian = solution_.row(e).tail(variables * variables).reshaped(variables, variables);
      }
      w.K[e] = w.K[e] - update;
    }
  }

  ButcherTableau t_;
  bool explicit_;
  int order_;
  bool self_adjoint_;
  NewtonSolver newton_;
  std::string error_;
  // Workspace, sized on the first step: later steps of the same size allocate nothing.
  Workspace<double> doubles_;
  Workspace<Jet2> jets_;
  std::vector<double> value_point_;
  std::vector<Jet2> residual_jets_;
  Eigen::VectorXd residual_;
  Eigen::MatrixXd newton_matrix_, df_, components_, solution_;
  Eigen::PartialPivLU<Eigen::MatrixXd> lu_;
};

}  // namespace varia::sdk
