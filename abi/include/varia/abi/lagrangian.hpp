// Lagrangian L : TQ -> R (paper, sec. 1), evaluated at one point (q, v) per call: q is the
// manifold point (m = point_size numbers), v the (left-trivialized) velocity (n = dim numbers).
// The gradient is [dL/dq (m), dL/dv (n)]; on a Lie group dL/dq is the gradient in the embedding.
#pragma once

#include "varia/abi/jet.hpp"
#include "varia/abi/kernels.hpp"
#include "varia/abi/plugin_object.hpp"

namespace varia {

class Lagrangian : public PluginObject {
 public:
  Kind kind() const noexcept final { return Kind::lagrangian; }
  virtual int position_size() const noexcept = 0;  // m
  virtual int velocity_size() const noexcept = 0;  // n

  // Any of value, gradient, hessian may be null and is then not computed. The Hessian of
  // z = (q, v) is written densely, column-major (m+n)^2, unless hessian_pattern() says sparse.
  virtual Status evaluate(const double* q, const double* v, double* value, double* gradient,
                          double* hessian) noexcept = 0;
  // The gradients at `count` points in one call: point i is z_i = (q, v) at points + i (m + n), and
  // its gradient [dL/dq, dL/dv] goes to gradients + i (m + n). The Galerkin construction evaluates
  // the quadrature nodes of a step's pass with it (the plugin boundary crossed once a pass, not
  // once a node). The default calls evaluate() point by point; the SDK's AutodiffLagrangian runs
  // the points through one loop with the model inlined. ABI 13.
  virtual Status gradients(int count, const double* points, double* gradients) noexcept {
    const int k = position_size() + velocity_size();
    for (int i = 0; i < count; ++i)
      if (const Status status = evaluate(points + i * k, points + i * k + position_size(), nullptr, gradients + i * k,
                                         nullptr))
        return status;
    return nullptr;
  }
  // Sparse Hessian: returns the number of stored entries and points rows/cols at their (row, col)
  // indices (lower and upper triangle both stored); -1 (the default) means dense.
  virtual int hessian_pattern(const int** /*rows*/, const int** /*cols*/) const noexcept {
    return -1;
  }
  // L = 1/2 v^T M v - V(q) with a constant mass matrix M: fills M (n x n, column-major) and
  // returns true. The constructions may then use explicit forms of their equations.
  virtual bool constant_mass_matrix(double* /*mass*/) const noexcept { return false; }
  // Whether L = 1/2 v^T M v - V(q) with a constant M, without writing M: for a sparse Lagrangian,
  // whose M (its Hessian's vv entries at any point) would not fit an n x n buffer. The Galerkin
  // construction then takes the explicit form where its equations are explicit. ABI 12.
  virtual bool has_constant_mass_matrix() const noexcept { return false; }
  // Kernels (kernels.hpp): whether the plugin runs the kernel of this call (its id, version and,
  // where the kernel says so, the arguments that decide it), and running it. The defaults offer
  // none; core then runs the same recurrence through the evaluations above. ABI 15 (replacing
  // ABI 13's verlet_steps and ABI 14's shoot).
  virtual bool offers(const KernelCall& /*call*/) const noexcept { return false; }
  virtual Status run(const KernelCall& /*call*/) noexcept {
    return "this Lagrangian runs no kernels (derive it from sdk::AutodiffLagrangian)";
  }
  // L and its gradient [dL/dq, dL/dv] at jet inputs (q, v): the jets of L(q(x), v(x)) and of its
  // gradient for the jet variables x (value may be null). The shooting construction integrates
  // the Euler-Lagrange vector field at jets with it (paper, sec. 3). The SDK's
  // AutodiffLagrangian implements it for every model.
  virtual Status gradient_jet(const Jet2* /*q*/, const Jet2* /*v*/, Jet2* /*value*/,
                              Jet2* /*gradient*/) noexcept {
    return "this Lagrangian does not evaluate at jets (derive it from sdk::AutodiffLagrangian)";
  }
  // Whether gradient_jet is implemented: constructions that need it refuse the Lagrangian when
  // they are built (`validate`, exit 2) rather than at the first step.
  virtual bool evaluates_at_jets() const noexcept { return false; }
  // Rows of L's Hessian in z = (q, v) at jet inputs, times directions: with k = m + n, the jets
  //   out[j count + r] = sum_c d2L/dz_{first + r} dz_c (q(x), v(x)) U_j[c],  r < count, j < directions,
  // U_j the k jets at U + j k (a direction may itself be a jet: the Euler-Lagrange field's L_vq v
  // takes U = (v, 0)), for jets of at most hessian_jet_variables() variables. The shooting
  // construction integrates the Euler-Lagrange field at jets with it when the mass matrix depends
  // on the point: the acceleration M^{-1} (L_q - L_vq v) (on a Lie group the Euler-Poincare field's
  // L_xixi and L_xig g') and its second-order jets need L's derivatives to fourth order, and only
  // these rows (the velocity's) and these directions (the velocity's unit vectors, and one more).
  // The caller sizes the request, so a model pays for what the field uses, not for (m + n)^2 jets.
  // The SDK's AutodiffLagrangian implements it for every model. ABI 19 (ABI 10's whole Hessian).
  virtual Status hessian_jet(const Jet2* /*q*/, const Jet2* /*v*/, int /*first*/, int /*count*/, int /*directions*/,
                             const Jet2* /*U*/, Jet2* /*out*/) noexcept {
    return "this Lagrangian does not give its Hessian at jets (derive it from sdk::AutodiffLagrangian)";
  }
  // The most jet variables hessian_jet takes (0: not implemented); constructions refuse a larger
  // need when they are built.
  virtual int hessian_jet_variables() const noexcept { return 0; }

  // The declared symmetry (Noether): a group name ("none", "SO(2)", "SO(3)", ...), the size of
  // its momentum map J(q, v) = <dL/dv, xi_Q(q)>, and the lifted action of a pseudo-random group
  // element drawn from `seed` on (q, v), for invariance checks.
  virtual const char* symmetry_group() const noexcept { return "none"; }
  virtual int momentum_size() const noexcept { return 0; }
  virtual Status momentum(const double* /*q*/, const double* /*v*/, double* /*J*/) noexcept {
    return "this Lagrangian declares no symmetry";
  }
  virtual Status act(unsigned /*seed*/, const double* /*q*/, const double* /*v*/, double* /*gq*/,
                     double* /*gv*/) noexcept {
    return "this Lagrangian declares no symmetry";
  }

  // The exact flow (q(t), v(t)) from (q0, v0), where one is known in closed form.
  virtual bool has_exact_solution() const noexcept { return false; }
  virtual Status exact_solution(const double* /*q0*/, const double* /*v0*/, double /*t*/,
                                double* /*q*/, double* /*v*/) noexcept {
    return "this Lagrangian has no exact solution";
  }

  // Where q holds the positions of particles (a particle system: particle i at
  // q[i * space_dim + k]), the dimension of their space, else 0; what a constraint on particles
  // binds to (Constraint::bind). ABI 16.
  virtual int space_dim() const noexcept { return 0; }
};

}  // namespace varia
