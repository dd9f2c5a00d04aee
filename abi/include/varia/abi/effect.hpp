// A potential term of a composed particle system (spec: "Composed systems: effects"): V(x) over
// the few coordinates x of q that the effect names, with its exact gradient and Hessian. The
// composite Lagrangian L = 1/2 sum_i m_i |v_i|^2 - sum_e V_e (composite.hpp) gathers each
// effect's coordinates, calls it, and scatters the results, so that an effect touches only its
// coordinates and the Hessian of L keeps the sparsity of the effects.
#pragma once

#include "varia/abi/jet.hpp"
#include "varia/abi/plugin_object.hpp"

namespace varia {

class Effect : public PluginObject {
 public:
  Kind kind() const noexcept final { return Kind::effect; }
  // Called once, before anything else: `particles` particles in `space_dim` dimensions with these
  // masses (q holds particle i at q[i * space_dim + k]). Fails if a named particle does not exist.
  virtual Status bind(int space_dim, int particles, const double* masses) noexcept = 0;
  // The coordinates V depends on: their number k, and their indices into q in *indices.
  virtual int coordinates(const int** indices) const noexcept = 0;
  // The stored entries of the k x k Hessian of V, as (row, col) indices into x (both triangles);
  // an entry may repeat, and its values then add.
  virtual int hessian_pattern(const int** rows, const int** cols) const noexcept = 0;
  // V(x) at the gathered coordinates x[j] = q[indices[j]]; the gradient dV/dx (k numbers); the
  // Hessian values, one per pattern entry. Any output may be null.
  virtual Status evaluate(const double* x, double* value, double* gradient,
                          double* hessian) noexcept = 0;
  // V and dV/dx at jet inputs x (k jets): the jets of V(x(t)) (value may be null) and of
  // dV/dx(x(t)) for the jet variables t. The shooting construction integrates a composite
  // Lagrangian's Euler-Lagrange field at jets with it (its second-order jets need V's derivatives
  // to third order). ABI 11.
  virtual Status gradient_jet(const Jet2* /*x*/, Jet2* /*value*/, Jet2* /*gradient*/) noexcept {
    return "this effect does not evaluate at jets";
  }
  // Whether gradient_jet is implemented: the composite Lagrangian evaluates at jets when all its
  // effects do.
  virtual bool evaluates_at_jets() const noexcept { return false; }
};

}  // namespace varia
