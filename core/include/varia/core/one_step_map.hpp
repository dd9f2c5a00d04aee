// A one-step method run directly on the Euler-Lagrange equations (the scene's construction
// "one-step"): the comparison methods of the paper's examples (sec. 3, "Examples": the implicit
// midpoint rule MID, the 2-stage Gauss method SRK4). (q0, p0) -> (q0, v0 = M^{-1} p0), one step
// of Psi_h on TQ, then p1 = M v1. Not variational unless the method is symplectic. On R^n the
// field is the MechanicalField; on a Lie group the Euler-Poincare field (lie_group_field.hpp),
// y = (g, xi): Runge-Kutta methods integrate it in the embedding (R^9 x R^3 on SO(3)), Lie group
// methods on the group (paper, sec. 2, Figure 1: RK, SRK, LGM). With holonomic constraints (on R^n,
// a constant mass matrix; an implicit method for quadratic constraints only) the method integrates their index-1
// form and each step is projected onto the constraint and its hidden constraint
// (constrained_field.hpp).
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>
#include <memory>
#include <string>
#include <vector>

#include "varia/core/discrete_hamiltonian_map.hpp"
#include "varia/abi/manifold.hpp"
#include "varia/core/constrained_field.hpp"
#include "varia/core/mechanical_field.hpp"
#include "varia/core/mechanics.hpp"
#include "varia/abi/one_step.hpp"

namespace varia {

class OneStepHamiltonianMap : public DiscreteHamiltonianMap {
 public:
  // Throws std::invalid_argument unless the Lagrangian matches the manifold (a vector space or a
  // Lie group) and the field can be formed (lie_group_field.hpp, mechanical_field.hpp), and with
  // constraints unless the manifold is a vector space and the method explicit or the constraints
  // quadratic (constrained_field.hpp).
  OneStepHamiltonianMap(Manifold& manifold, Lagrangian& lagrangian, OneStepMethod& method,
                        SolverOptions options, HolonomicConstraints* constraints = nullptr);
  int point_size() const override { return m_; }
  int dim() const override { return n_; }
  // Empty where the Lagrangian evaluates at jets (on R^n and on a Lie group), and with constraints
  // where they are quadratic.
  std::string tangent_map_refusal() const override;
 protected:
  void take_step(const double* q0, const double* p0, double t0, double h, double* q1, double* p1) override;
  // The step, then the method's step at first-order jets along the directions: a one-step method
  // steps jets with the exact derivatives of Psi_h (one_step.hpp), which is the implicit function
  // theorem on its stage equations (Runge-Kutta methods commute with linearization; a Lie group
  // method's exponentials are differentiated as they are). In passes of at most the field's
  // jet_variables() directions. On a Lie group the directions and images are in the natural charts
  // at g0 and g1 (seed(), image()). With constraints the jets are projected as the step is, so the
  // map differentiated is the projected one (on and off the constraint manifold).
  void take_tangent_step(const double* q0, const double* p0, double t0, double h, double* q1, double* p1, int count,
                         const double* directions, double* images) override;

 public:
  // The method's stage solves (zeros for explicit methods).
  const SolverStatistics& solver_statistics() const override { return statistics_; }
  const EvaluationCounters& evaluations() const override { return lagrangian_.counters(); }

 private:
  void prepare_group_tangent();
  void seed(const double* dx);
  void image(double* out) const;

  Manifold& manifold_;
  LagrangianEvaluator lagrangian_;
  std::unique_ptr<EulerLagrangeField> field_;
  ConstrainedField* constrained_ = nullptr;  // field_, with constraints
  OneStepMethod& method_;
  int m_, n_;  // point size, dimension
  // The state is (q, xi) with the momenta converted by the Legendre transform where the field is in
  // (q, v) without a constant mass matrix (on a Lie group), with these options.
  bool tangent_;
  SolverOptions options_;
  SolverStatistics statistics_;
  Eigen::VectorXd y0_, y1_;
  std::vector<Jet2> jets0_, jets1_;  // the tangent map's state at jets
  Eigen::VectorXd column_;           // a direction's derivative of the state (m + n)
  // On a Lie group (prepare_group_tangent): D(g0), C1^T, L's Hessians and L_xixi's LU at the ends.
  std::vector<Jet2> point_jets_, generator_jets_;
  Eigen::MatrixXd generators_, chart_inverse_, hessian0_, hessian1_;
  Eigen::VectorXd gradient_, local_value_;
  std::vector<double> local_hessian_;
  Eigen::PartialPivLU<Eigen::MatrixXd> inertia_lu_;
  SolverStatistics tangent_stages_;  // the jet steps' stage solves (not the run's)
};

}  // namespace varia
