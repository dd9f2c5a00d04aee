// The vector field that a one-step method integrates for the shooting construction (paper,
// sec. 3) and the one-step construction, on R^n:
//   tangent form (q, v):    q' = v,        v' = M^{-1} (dL/dq - d2L/dv dq v)   (Euler-Lagrange,
//                           M = d2L/dv2 (q, v); for L = 1/2 v^T M v - V(q) with a constant mass
//                           matrix, v' = M^{-1} dL/dq),
//   cotangent form (q, p):  q' = v(q, p),  p' = dL/dq (q, v(q, p))    (Hamilton's equations of
//                           the Legendre transform H(q, p) = <p, v> - L(q, v), dL/dv (q, v) = p,
//                           paper, sec. 3 "Generalizations"), for any regular Lagrangian: v(q, p)
//                           is M^{-1} p for a constant mass matrix, else the exact inverse Legendre
//                           transform, solved by Newton's method at doubles and at jets.
// The cotangent form needs L's derivatives to second order for the field's Jacobian and to third
// order for its second-order jets, which dL/dv at jets gives; the tangent form of a
// configuration-dependent mass matrix needs them to third and fourth order, which L's Hessian at
// jets gives (Lagrangian::hessian_jet; refused for a Lagrangian without it).
// With forces f(t, q, v) (force.hpp) the field is that of the forced Euler-Lagrange equations,
// d/dt dL/dv - dL/dq = f (Marsden & West 2001, sec. 3.2): M v' = L_q + f, or p' = L_q + f; the
// time is then the state's last number, t' = 1 (the methods integrate autonomous fields).
// The field's values come from L's exact derivatives, at doubles and at jets. The field also
// drives one step of a one-step plugin, turning its Status into the right exception.
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>
#include <exception>
#include <string>
#include <vector>

#include "varia/core/discrete_hamiltonian_map.hpp"
#include "varia/abi/force.hpp"
#include "varia/abi/manifold.hpp"
#include "varia/core/mechanics.hpp"
#include "varia/abi/one_step.hpp"

namespace varia {

enum class PhaseSpace { tangent, cotangent };

// Throws std::invalid_argument unless the manifold is a vector space (Rn) whose dimension the
// Lagrangian's sizes match: the constructions that integrate a MechanicalField need it.
void require_vector_space(const Manifold& manifold, const Lagrangian& lagrangian,
                          const char* construction);

// x = M^{-1} b at jets, for a mass matrix M whose entries are jets (the velocity block of L's
// Hessian at jets: MechanicalField's acceleration, LieGroupField's inertia). M's values are
// inverted at doubles (M0), x = M0^{-1} b, then two corrections x += M0^{-1} (b - M x): the error's
// value part is zero and each correction multiplies it by I - M0^{-1} M, whose value part is zero,
// so that the first and then the second derivatives become exact. Workspace sized once.
class JetLinearSolve {
 public:
  explicit JetLinearSolve(int n);
  // M(r, c) is M[c * stride + r] (a block of a column-major matrix of jets); b and x distinct.
  void solve(const Jet2* M, int stride, const Jet2* b, Jet2* x);

 private:
  int n_;
  Eigen::MatrixXd inverse_, identity_;  // M0^{-1}
  Eigen::PartialPivLU<Eigen::MatrixXd> lu_;
  std::vector<Jet2> residual_, correction_;
};

// The rows of L's Hessian at jets that an Euler-Lagrange field with a configuration-dependent mass
// matrix takes (Lagrangian::hessian_jet), for L(q, v) of m + n numbers: the velocity block L_vv
// (the directions e_v) and L_vq u for one direction u of the point's numbers (g' on a Lie group,
// v on R^n), n (n + 1) jets in one request instead of L's (m + n)^2.
class VelocityHessianJet {
 public:
  VelocityHessianJet(int m, int n);
  // At jets (q, v), with u's m numbers.
  void evaluate(LagrangianEvaluator& lagrangian, const Jet2* q, const Jet2* v, const Jet2* u);
  // L_vv, column-major (stride n), and (L_vq u)_r.
  const Jet2* inertia() const { return out_.data(); }
  const Jet2& along(int r) const { return out_[static_cast<std::size_t>(n_) * n_ + r]; }

 private:
  int m_, n_;
  std::vector<Jet2> directions_, out_;  // the n unit directions (constant), then u's; the products
};

// Whether the Lagrangian declares a constant mass matrix (Lagrangian::constant_mass_matrix).
bool declares_constant_mass(const Lagrangian& lagrangian);

// The Euler-Lagrange vector field of a Lagrangian on a state y = (q, w): q the point (point_size
// numbers), w the velocity or momentum. It drives one step of a one-step plugin, turning its
// Status into the right exception; the derived fields give f for their phase space.
class EulerLagrangeField : public VectorField {
 public:
  // mass() and inverse_mass() are those of a Lagrangian declaring a constant mass matrix
  // (constant_mass()); the derived fields that need one refuse the others.
  explicit EulerLagrangeField(LagrangianEvaluator& lagrangian);
  bool constant_mass() const { return constant_mass_; }
  // The most variables the field's jets may hold (eval at jets): Jet2's capacity, or fewer where
  // the Lagrangian's derivatives at jets take fewer. The shooting construction propagates its
  // sensitivities in passes of at most this many directions (shooting.hpp).
  virtual int jet_variables() const { return kMaxJetVariables; }

  // y1 = Psi_h(y0) by `method`, its stage iterations recorded in `stages`. Throws
  // NumericalFailure (stage equations that do not converge, a non-finite state) or PluginFault.
  void step(OneStepMethod& method, double h, const double* y0, double* y1,
            SolverStatistics& stages);
  void step(OneStepMethod& method, double h, const Jet2* y0, Jet2* y1, SolverStatistics& stages);

  const Eigen::MatrixXd& mass() const { return mass_; }
  const Eigen::MatrixXd& inverse_mass() const { return inverse_mass_; }
  // x = M^{-1} w, at doubles or jets: the velocity of a momentum, the acceleration of a force.
  void inverse_mass(const double* w, double* x) const;
  void inverse_mass(const Jet2* w, Jet2* x) const;

 protected:
  // Runs f, turning an exception into a Status (kept to be rethrown after the step).
  template <class F>
  Status guard(F&& f) noexcept {
    try {
      f();
      return nullptr;
    } catch (const std::exception& e) {
      message_ = e.what();
    } catch (...) {
      message_ = "unknown exception";
    }
    pending_ = std::current_exception();
    return message_.c_str();
  }

  LagrangianEvaluator& lagrangian_;
  int n_;
  bool constant_mass_;
  Eigen::MatrixXd mass_, inverse_mass_;

 private:
  template <class T>
  void advance(OneStepMethod& method, double h, const T* y0, T* y1, SolverStatistics& stages);

  std::exception_ptr pending_;  // what made the last callback fail, rethrown after the step
  std::string message_;
};

// On R^n: y = (q, v) or (q, p), N = 2n; with forces y = (q, v, t) or (q, p, t), N = 2n + 1.
class MechanicalField final : public EulerLagrangeField {
 public:
  // The tangent form throws std::invalid_argument unless the Lagrangian declares a constant mass
  // matrix or gives its Hessian at jets of at least 2 variables. The forces (may be null or empty:
  // none) are applied while forced() is on.
  MechanicalField(LagrangianEvaluator& lagrangian, PhaseSpace space, Forces* forces = nullptr);
  int size() const noexcept override { return 2 * n_ + (clock() ? 1 : 0); }
  // The tangent form with a configuration-dependent mass matrix: L's Hessian at jets bounds them.
  int jet_variables() const override;
  Status eval(const double* y, double* f) noexcept override;
  Status eval(const Jet2* y, Jet2* f) noexcept override;
  Status jacobian(const double* y, double* f, double* df) noexcept override;

  // The velocity of state y: its own w (tangent), or v(q, w) (cotangent: M^{-1} w, or the inverse
  // Legendre transform at jets) in a workspace, valid until the next call.
  const Jet2* velocity(const Jet2* y);
  // p = dL/dv (q, v) at doubles: the momentum of a velocity (a Newton guess on the cotangent side).
  void momentum(const double* q, const double* v, double* p);
  // v(q, p) at doubles, the inverse: M^{-1} p, or the exact inverse Legendre transform.
  void velocity_of(const double* q, const double* p, double* v) {
    velocity_of_momentum(q, p);
    Eigen::Map<Eigen::VectorXd>(v, n_) = v_;
  }

  // The state's positions as offsets from `origin` (n jets, kept by the caller; null: none): the
  // field is evaluated at origin + offset. Every Runge-Kutta method commutes with the translation,
  // and the propagated offsets carry errors of their own size, not of |q| (the shooting
  // construction's endpoints, shooting.hpp).
  void set_origin(const Jet2* origin) { origin_ = origin; }
  // The positions of state y: origin + y's offsets (in a workspace, valid until the next call),
  // or y's own.
  const Jet2* point(const Jet2* y);
  // Whether the state carries the time (the field has forces), and whether they are applied.
  bool clock() const { return forces_ != nullptr; }
  void set_forced(bool forced) { forced_ = forced && clock(); }
  // f(t, y[2n], q, v) at jets q = y, v = velocity(y + n): the value, and the derivatives through
  // the forces' Jacobian, f_x = f_q q_x + f_v v_x, f_xx = f_q q_xx + f_v v_xx. The Force interface
  // gives no second derivatives of f: the Hessian part is exact for forces affine in (q, v), as
  // every bundled force is (damping, periodic-force).
  void force(const Jet2* y, const Jet2* v, Jet2* f);

 private:
  // f(t, q, v) at jets q, v.
  void force_at(const Jet2* q, const Jet2* v, double t, Jet2* f);
  // The tangent form with a configuration-dependent mass matrix.
  bool general_tangent() const { return space_ == PhaseSpace::tangent && !constant_mass_; }
  void acceleration(double* a);
  void acceleration(const Jet2* q, const Jet2* v, Jet2* a);
  void general_tangent_jacobian(const double* y, double* f, double* df);
  // Adds the forces at the values of y (velocity v_) to gradient_.head(n) (= L_q + f), and with
  // `jacobian` their Jacobian to the rows of hessian_ (d(L_q + f)/d(q, v)).
  void add_forces(const double* y, const double* q, bool jacobian);
  const double* point(const double* y);
  // v_ = v(q, p) at doubles: M^{-1} p, or the inverse Legendre transform from the last v_.
  void velocity_of_momentum(const double* q, const double* p);
  // The cotangent form's Jacobian [v_q, v_p; (L_q + f)_q + (L_q + f)_v v_q, (L_q + f)_v v_p] from
  // hessian_ (with the forces' rows), v_q = -M^{-1} L_vq and v_p = M^{-1} at (q, v_).
  void cotangent_jacobian(Eigen::Ref<Eigen::MatrixXd> J);

  PhaseSpace space_;
  Forces* forces_;
  bool forced_ = false;
  Eigen::VectorXd force_, force_jacobian_, position_;
  const Jet2* origin_ = nullptr;
  Eigen::VectorXd absolute_;
  std::vector<Jet2> absolute_jet_;
  std::vector<Jet2> force_jet_;
  // Workspace, sized once.
  Eigen::VectorXd v_, gradient_;
  Eigen::MatrixXd hessian_, velocity_q_;  // v_q in cotangent_jacobian(), M^{-1} at the values in velocity()
  Eigen::MatrixXd identity_;
  Eigen::VectorXd rhs_;
  Eigen::PartialPivLU<Eigen::MatrixXd> mass_lu_;  // L_vv at the last state (not constant_mass())
  std::vector<Jet2> v_jet_, gradient_jet_, legendre_residual_;  // the last also acceleration()'s right side
  VelocityHessianJet velocity_hessian_jet_;
  std::vector<Jet2> seed_, acceleration_jet_, correction_jet_;  // correction_jet_: M^{-1} times a residual
  JetLinearSolve acceleration_solve_;  // sized for the general tangent form only
  int hessian_jet_variables_;  // the Lagrangian's (Lagrangian::hessian_jet_variables)
  SolverOptions legendre_options_;
};

}  // namespace varia
