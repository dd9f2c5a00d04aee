// The Stormer-Verlet recurrence of the Galerkin construction's explicit form: degree 1 with an
// endpoint quadrature rule (weights b0 at 0, b1 at 1) for L = 1/2 v.Mv - V(q) with a constant mass
// matrix M (paper, sec. 2: degree 1 with the trapezoidal rule is Stormer-Verlet). Carried in the
// position increment d = h v, a step is
//   q += d;  f = dL/dq(q);  d += K f,   K = h^2 (b0 + b1) M^{-1},
// `steps` times in place (galerkin.cpp derives it). One piece of code for both places that run it:
// the core, whose `force` is a plugin call a step (GalerkinDiscreteLagrangian::explicit_advance),
// and the SDK inside the plugin, with the model's dL/dq inlined (kernel::StormerVerletSteps), so that
// both take the same steps to the bit.
#pragma once

namespace varia {

// force(q, f) writes dL/dq at q into f. Vector and Matrix are Eigen types (fixed-size ones keep the
// state in registers); nothing is allocated.
template <class Vector, class Matrix, class Force>
inline void stormer_verlet_steps(Vector& q, Vector& d, Vector& f, const Matrix& K, long steps, Force&& force) {
  for (long k = 0; k < steps; ++k) {
    q += d;
    force(q, f);
    d.noalias() += K * f;
  }
}

}  // namespace varia
