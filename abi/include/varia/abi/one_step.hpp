// One-step methods Psi_h for an autonomous ODE y' = f(y) on R^N (paper, sec. 3: the method that
// a shooting-based discrete Lagrangian is built from). The caller owns the vector field and
// passes it to every step; a method steps both doubles and second-order jets (jet.hpp), so that
// the shooting construction obtains the exact first and second sensitivities of the propagation.
#pragma once

#include "varia/abi/kernels.hpp"
#include "varia/abi/jet.hpp"
#include "varia/abi/plugin_object.hpp"

namespace varia {

// The right-hand side f, provided by the caller (the core), called by the method. Each call
// returns a Status like every plugin call; a failure ends the step.
class VectorField {
 public:
  virtual ~VectorField() = default;
  virtual int size() const noexcept = 0;  // N
  virtual Status eval(const double* y, double* f) noexcept = 0;
  virtual Status eval(const Jet2* y, Jet2* f) noexcept = 0;
  // f(y) and its exact Jacobian df/dy (N x N, column-major): the Newton matrix of implicit stages.
  virtual Status jacobian(const double* y, double* f, double* df) noexcept = 0;

  // The state space as a Lie group acting on itself, for Lie group methods (Crouch-Grossman,
  // RKMK; paper, sec. 2 "G-equivariant interpolants"): y' = y . xi(y) with xi(y) in the algebra
  // (algebra_size() numbers), and move(y, xi) = y . exp(xi). The defaults are those of R^N, the
  // group of translations: xi = f, y . exp(xi) = y + xi; a Lie group method is then a Runge-Kutta
  // method. On TSO(3) = SO(3) x R^3 the field gives xi = (Omega, Omega') and moves R exp(Omega).
  virtual int algebra_size() const noexcept { return size(); }
  virtual Status algebra(const double* y, double* xi) noexcept { return eval(y, xi); }
  virtual Status algebra(const Jet2* y, Jet2* xi) noexcept { return eval(y, xi); }
  virtual Status move(const double* y, const double* xi, double* moved) noexcept {
    return translate(y, xi, moved);
  }
  virtual Status move(const Jet2* y, const Jet2* xi, Jet2* moved) noexcept {
    return translate(y, xi, moved);
  }

 private:
  template <class T>
  Status translate(const T* y, const T* xi, T* moved) noexcept {
    for (int r = 0; r < size(); ++r) moved[r] = y[r] + xi[r];
    return nullptr;
  }
};

// What an implicit method reports about the nonlinear solves of one step (zeros for explicit
// methods). On failure to converge the step returns a Status and sets converged = false; the
// caller then raises a numerical failure rather than a plugin fault.
struct StageSolve {
  int iterations = 0;     // Newton iterations of the stage equations
  double residual = 0.0;  // the last residual norm
  bool converged = true;
};

class OneStepMethod : public PluginObject {
 public:
  Kind kind() const noexcept final { return Kind::one_step; }
  // The order p of the global error, whether Psi_h is self-adjoint (Psi_h = Psi_{-h}^{-1}, paper,
  // sec. 3 "Symmetric shooting-based discrete Lagrangians"), and the maps of R^N it commutes
  // with ("affine" for Runge-Kutta methods: every tangent-lifted linear or affine group action
  // on R^n, paper, sec. 3 "Group-invariant shooting-based discrete Lagrangians"; "left" for Lie
  // group methods: left multiplication on the group, and affine maps where the group is R^N).
  virtual int order() const noexcept = 0;
  virtual bool self_adjoint() const noexcept = 0;
  virtual const char* equivariance() const noexcept = 0;
  // Tolerance and iteration limit of the stage equations of implicit methods.
  virtual void set_solver(double tolerance, int max_iterations) noexcept = 0;
  // An explicit Runge-Kutta method's Butcher tableau (stages = 0 for any other method): its step
  // is then explicit_runge_kutta_step with it, and the shooting construction may run its shots
  // inside the Lagrangian's plugin (kernel::ExplicitShot). The pointers stay valid while the
  // method lives. ABI 14.
  virtual RungeKuttaTableau explicit_tableau() const noexcept { return {}; }
  // y1 = Psi_h(y0) for y in R^N, N = field.size(). At jets, y1 carries the exact derivatives of
  // Psi_h(y0) with respect to the variables of y0. Every number of y0 carries all of them (with
  // zero derivatives where it does not depend on one), and the field's jets may depend on them
  // through the field itself (the shooting construction's origin on R^n), so a method reads the
  // number of variables off any number of y0.
  virtual Status step(VectorField& field, double h, const double* y0, double* y1,
                      StageSolve* report) noexcept = 0;
  virtual Status step(VectorField& field, double h, const Jet2* y0, Jet2* y1,
                      StageSolve* report) noexcept = 0;
};

}  // namespace varia
