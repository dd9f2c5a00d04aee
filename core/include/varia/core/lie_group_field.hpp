// The Euler-Lagrange (Euler-Poincare) vector field on TG = G x g of a Lagrangian
// L(g, xi) = 1/2 xi . J xi - V(g) with a constant inertia J, on a Lie group G that its manifold
// declares (manifold.hpp): the field that the one-step methods integrate for the one-step and
// shooting constructions on a group (paper, sec. 2, the comparison methods of Figure 1; sec. 3).
// With the state y = (g, xi) in the embedding (point_size() + dim() numbers),
//   g' = g xi = D(g) xi,    J xi' = ad*_xi (J xi) + D(g)^T dL/dg,
// D(g) the group's generators at g (Manifold::generators: the tangent vectors g e_a), so that
// D(g)^T dL/dg is the left-trivialized derivative of L in g (the potential's torque), and
// ad*_xi mu = (ad_xi)^T mu the coadjoint action, from the structure constants [e_a, e_b] that the
// natural chart's velocity gives at second order (dexp_{-xi} v = v - 1/2 [xi, v] + ...).
// Runge-Kutta methods integrate the field in the embedding and leave the group; a Lie group
// method sees TG as the group G x g acting on itself: xi(y) = (xi, xi') in g x g and
// y . exp(eta) = (g exp(eta_g), xi + eta_xi) (Manifold::translate at jets, retract at doubles).
// Nothing here names a particular group.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "varia/abi/manifold.hpp"
#include "varia/core/mechanical_field.hpp"

namespace varia {

class LieGroupField final : public EulerLagrangeField {
 public:
  // Throws std::invalid_argument unless the manifold is a Lie group (not a vector space) whose
  // sizes the Lagrangian matches, with a constant inertia (EulerLagrangeField).
  LieGroupField(Manifold& manifold, LagrangianEvaluator& lagrangian);
  int size() const noexcept override { return m_ + n_; }
  Status eval(const double* y, double* f) noexcept override;
  Status eval(const Jet2* y, Jet2* f) noexcept override;
  // The exact Jacobian, from the field at jets (blocks of kMaxJetVariables state numbers).
  Status jacobian(const double* y, double* f, double* df) noexcept override;

  int algebra_size() const noexcept override { return 2 * n_; }
  Status algebra(const double* y, double* xi) noexcept override;
  Status algebra(const Jet2* y, Jet2* xi) noexcept override;
  Status move(const double* y, const double* xi, double* moved) noexcept override;
  Status move(const Jet2* y, const Jet2* xi, Jet2* moved) noexcept override;

 private:
  // The structure constants [e_a, e_b]_c at structure_[(c n + a) n + b], from the chart at the
  // first point the field sees (the velocity part of the chart does not depend on it).
  void learn_structure(const double* point);
  // The generators D(g) (m x n, component-major) and dL/d(g, xi) at y, in the workspace of T.
  void prepare(const double* y);
  void prepare(const Jet2* y);
  // From the prepared D and gradient: g' = D xi into velocity unless it is null, xi' into rate.
  template <class T>
  void rates(const T* y, const T* D, const T* gradient, T* velocity, T* rate);

  Manifold& manifold_;
  int m_;
  std::vector<double> structure_;
  // Workspace, sized once.
  std::vector<double> generators_, gradient_, chart_hessian_;
  std::vector<Jet2> point_jet_, generators_jet_, gradient_jet_, momentum_jet_, torque_jet_, y_jet_,
      f_jet_;
  Eigen::VectorXd momentum_, torque_;
};

}  // namespace varia
