// Configuration manifold Q with a natural chart (paper, sec. 2 "Natural charts"):
// psi_{q0}^{-1}(xi) = q0 exp(xi) (retract) and psi_{q0}(q) = log(q0^{-1} q) (local).
// A point is point_size() numbers (n on R^n; 9 on SO(3), a row-major rotation matrix); tangent
// vectors, velocities and momenta are dim() numbers, left-trivialized on a Lie group.
#pragma once

#include "varia/core/jet.hpp"
#include "varia/core/plugin_object.hpp"

namespace varia {

class Manifold : public PluginObject {
 public:
  Kind kind() const noexcept final { return Kind::manifold; }
  virtual int point_size() const noexcept = 0;
  virtual int dim() const noexcept = 0;
  // True when the natural chart is affine, q = q0 + xi (a vector space): the constructions then
  // assemble their equations directly in the coordinates, with the Lagrangian's sparsity.
  virtual bool is_vector_space() const noexcept = 0;
  virtual Status retract(const double* q0, const double* xi, double* q) noexcept = 0;
  virtual Status local(const double* q0, const double* q, double* xi) noexcept = 0;
  // Checks that q is a point of the manifold (to a tolerance); fills `why` when it is not.
  virtual bool contains(const double* q, char* why, int why_size) noexcept = 0;
  // How far q lies off the manifold in its embedding, for the run's drift observables:
  // ||I - R^T R||_F on SO(3) (the paper's orthogonality error); 0 where every point is valid.
  virtual double constraint_error(const double* /*q*/) const noexcept { return 0.0; }
  // The natural chart to second order, for the Galerkin construction on a Lie group (paper,
  // sec. 2, "Natural charts"): with n = dim(),
  //   point:    q0 exp(eta) exp(xi) at eta = 0, point_size() jets in the 2n variables (eta, xi);
  //   velocity: the left-trivialized velocity dexp_{-xi}(xi_dot) of the curve q0 exp(xi(t)) with
  //             xi' = xi_dot, n jets in the 2n variables (xi, xi_dot).
  // Either output may be null. On R^n: q0 + eta + xi and xi_dot. Needs 2n <= kMaxJetVariables.
  virtual Status chart_jets(const double* /*q0*/, const double* /*xi*/, const double* /*xi_dot*/,
                            Jet2* /*point*/, Jet2* /*velocity*/) noexcept {
    return "this manifold does not provide its natural chart at jets";
  }
  // The chart's inverse at jets, for the shooting construction's boundary condition (paper,
  // sec. 3 with sec. 2 "Natural charts"): xi = local(q0, q) = log(q0^{-1} q) (dim() jets) of a
  // point q given as point_size() jets; q0 is a constant. On R^n: q - q0.
  virtual Status local_jets(const double* /*q0*/, const Jet2* /*q*/, Jet2* /*xi*/) noexcept {
    return "this manifold does not provide its natural chart's inverse at jets";
  }
};

}  // namespace varia
