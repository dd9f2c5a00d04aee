// Kernels: a construction's inner loop that a Lagrangian's plugin may run with its model inlined,
// so that the plugin boundary is crossed once for many evaluations (part of the ABI). The
// construction's algorithm lives once, in core: each kernel is a recurrence that core defines and
// also runs itself, through the Lagrangian's evaluations, whenever a plugin does not offer it. A
// plugin offers kernels through one entry point (Lagrangian::offers and Lagrangian::run), so that
// a new kernel, or a new version of one, changes no virtual function and no plugin built before
// it: a plugin that does not know a kernel's id or version does not offer it, and core falls back.
// Only plain types here.
#pragma once

#include "varia/abi/jet.hpp"

namespace varia {

// A Runge-Kutta method's Butcher tableau, viewed: Y_i = y0 + h sum_j a_ij K_j, K_i = f(Y_i),
// y1 = y0 + h sum_i b_i K_i; a is s x s, column-major. A method that is not an explicit
// Runge-Kutta method gives stages = 0 (OneStepMethod::explicit_tableau).
struct RungeKuttaTableau {
  int stages = 0;
  const double* a = nullptr;
  const double* b = nullptr;
  const double* c = nullptr;
  double at(int i, int j) const { return a[j * stages + i]; }
};

// What a shot is run with: the explicit method, the quadrature's nodes 0 = c_0 < ... < c_{k-1} = 1
// with their weights (zero where the rule has no node), and M^{-1}.
struct ShotPlan {
  RungeKuttaTableau method;
  int nodes = 0;
  const double* node = nullptr;
  const double* weight = nullptr;
  int n = 0;                             // the dimension of R^n
  const double* inverse_mass = nullptr;  // n x n, column-major
};

// A call of a kernel: its id and version, and its arguments (the struct of that id and version).
struct KernelCall {
  int id = 0;
  int version = 0;
  void* arguments = nullptr;
};

namespace kernel {

// Galerkin's explicit form (degree 1, an endpoint rule, L = 1/2 v^T M v - V(q) with a constant M:
// Stormer-Verlet), `steps` steps in place (stormer_verlet.hpp: q += d; f = dL/dq(q); d += K f, with
// q, d, f n numbers and K n x n, column-major), for a dense L with m = n. The numbers must be those
// of the same recurrence with dL/dq from evaluate() (the conformance suite checks it); non-finite
// numbers are left as they come (the caller checks the result).
struct StormerVerletSteps {
  static constexpr int id = 1, version = 1;
  double* q = nullptr;
  double* d = nullptr;
  double* f = nullptr;
  const double* K = nullptr;
  long steps = 0;
};

// The shooting construction's shot (explicit_shot.hpp: an explicit Runge-Kutta method, L = 1/2 v^T
// M v - V(q) with a constant M on R^n with m = n, no forces): the action S into `action` and the
// end's offsets q^n - (q0 + eta) into `offsets` (n), jets of the 2n variables x = (eta, w0). The
// numbers must be those of explicit_shot with dL/dq from gradient_jet (the conformance suite checks
// it). The Hessians need only their columns in w0, which are all that the shooting Newton's
// Jacobian reads (shooting.hpp); the block in eta x eta may be left as anything. Offered for a
// plan (its n and number of stages): `plan` is set when offers() is asked.
struct ExplicitShot {
  static constexpr int id = 2, version = 1;
  const ShotPlan* plan = nullptr;
  const double* q0 = nullptr;
  const double* w0 = nullptr;
  double h = 0.0;
  Jet2* action = nullptr;
  Jet2* offsets = nullptr;
};

// The call of a kernel with these arguments.
template <class Arguments>
KernelCall call(Arguments& arguments) {
  return {Arguments::id, Arguments::version, &arguments};
}
// A call's arguments as the kernel Arguments, or null where the call is of another kernel or
// version.
template <class Arguments>
Arguments* arguments(const KernelCall& call) {
  return call.id == Arguments::id && call.version == Arguments::version ? static_cast<Arguments*>(call.arguments)
                                                                          : nullptr;
}

}  // namespace kernel
}  // namespace varia
