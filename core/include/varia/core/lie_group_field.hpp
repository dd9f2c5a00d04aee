// The Euler-Lagrange (Euler-Poincare) vector field on TG = G x g of a Lagrangian L(g, xi), on a
// Lie group G that its manifold declares (manifold.hpp): the field that the one-step methods
// integrate for the one-step and shooting constructions on a group (paper, sec. 2, the comparison
// methods of Figure 1; sec. 3). With the state y = (g, xi) in the embedding (point_size() + dim()
// numbers), the Euler-Poincare equations d/dt dL/dxi = ad*_xi dL/dxi + D(g)^T dL/dg read
//   g' = g xi = D(g) xi,    L_xixi xi' = ad*_xi mu + D(g)^T dL/dg - L_xig g',   mu = dL/dxi,
// D(g) the group's generators at g (Manifold::generators: the tangent vectors g e_a), so that
// D(g)^T dL/dg is the left-trivialized derivative of L in g (the potential's torque), and
// ad*_xi mu = (ad_xi)^T mu the coadjoint action, from the structure constants [e_a, e_b] that the
// natural chart's velocity gives at second order (dexp_{-xi} v = v - 1/2 [xi, v] + ...). With a
// constant inertia J (L = 1/2 xi . J xi - V(g): the rigid body, the heavy top) mu = J xi, L_xig = 0
// and the solve is J^{-1}; otherwise (a chain of bodies, whose inertia depends on their attitudes)
// L's Hessian gives L_xixi and L_xig, at doubles (and at jets its velocity rows give L_xixi and
// L_xig g', Lagrangian::hessian_jet), and the solve at jets is MechanicalField's (JetLinearSolve, mechanical_field.hpp).
// Runge-Kutta methods integrate the field in the embedding and leave the group; a Lie group
// method sees TG as the group G x g acting on itself: xi(y) = (xi, xi') in g x g and
// y . exp(eta) = (g exp(eta_g), xi + eta_xi) (Manifold::translate at jets, retract at doubles).
// Nothing here names a particular group.
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>
#include <vector>

#include "varia/abi/manifold.hpp"
#include "varia/core/mechanical_field.hpp"

namespace varia {

// The structure constants [e_a, e_b]_c of a Lie group's algebra, at [(c n + a) n + b], read off its
// natural chart at `point`: dexp_{-xi} v = v - [xi, v] / 2 + O(|xi|^2 |v|), so the chart velocity's
// mixed second derivative in (xi_a, v_b) at 0 is -[e_a, e_b] / 2 (the velocity part of the chart
// does not depend on the point).
std::vector<double> structure_constants(Manifold& manifold, const double* point);
// ad_a^T v for each column a of `directions`: (ad_a^T v)_b = v . [a, e_b], from the structure
// constants (the tangent maps' Baker-Campbell-Hausdorff terms: galerkin_chart_tangent.cpp,
// shooting_solve.cpp).
Eigen::MatrixXd coadjoint(const std::vector<double>& structure, const Eigen::Ref<const Eigen::MatrixXd>& directions,
                          const Eigen::Ref<const Eigen::VectorXd>& v);

class LieGroupField final : public EulerLagrangeField {
 public:
  // Throws std::invalid_argument unless the manifold is a Lie group (not a vector space) whose
  // sizes the Lagrangian matches, with a constant inertia or its Hessian at jets.
  LieGroupField(Manifold& manifold, LagrangianEvaluator& lagrangian);
  // The Hessian at jets caps the jets' variables when the inertia is not constant.
  int jet_variables() const override;
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
  // From the prepared D and gradient (and Hessian): g' = D xi into velocity unless it is null, xi'
  // into rate.
  template <class T>
  void rates(const T* y, const T* D, const T* gradient, T* velocity, T* rate);
  // L_xig at the prepared Hessian: row b (of xi), column k (of g).
  double mixed(int b, int k) const { return hessian_(m_ + b, k); }
  // velocity = D xi, the group velocity g'.
  template <class T>
  void group_velocity_of(const T* D, const T* xi, T* velocity) const;
  // rate = L_xixi^{-1} torque (J^{-1} for a constant inertia).
  void solve_inertia(const double* torque, double* rate);
  void solve_inertia(const Jet2* torque, Jet2* rate);

  Manifold& manifold_;
  int m_;
  std::vector<double> structure_;
  // Workspace, sized once.
  std::vector<double> generators_, gradient_;
  std::vector<Jet2> point_jet_, generators_jet_, gradient_jet_, momentum_jet_, torque_jet_, y_jet_,
      f_jet_;
  Eigen::VectorXd momentum_, torque_, group_velocity_;
  std::vector<Jet2> group_velocity_jet_;
  // A configuration-dependent inertia: L's Hessian at doubles, its velocity rows at jets (L_xixi
  // and L_xig g'), L_xixi's LU at doubles and its solve at jets (sized in the constructor).
  int hessian_jet_variables_ = 0;
  Eigen::MatrixXd hessian_;
  Eigen::PartialPivLU<Eigen::MatrixXd> inertia_lu_;
  VelocityHessianJet velocity_hessian_jet_;
  JetLinearSolve inertia_solve_;
};

}  // namespace varia
