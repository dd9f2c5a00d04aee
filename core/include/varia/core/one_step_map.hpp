// A one-step method run directly on the Euler-Lagrange equations (the scene's construction
// "one-step"): the comparison methods of the paper's examples (sec. 3, "Examples": the implicit
// midpoint rule MID, the 2-stage Gauss method SRK4). (q0, p0) -> (q0, v0 = M^{-1} p0), one step
// of Psi_h on TQ, then p1 = M v1. Not variational unless the method is symplectic. On R^n the
// field is the MechanicalField; on a Lie group the Euler-Poincare field (lie_group_field.hpp),
// y = (g, xi): Runge-Kutta methods integrate it in the embedding (R^9 x R^3 on SO(3)), Lie group
// methods on the group (paper, sec. 2, Figure 1: RK, SRK, LGM).
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "varia/core/discrete_hamiltonian_map.hpp"
#include "varia/abi/manifold.hpp"
#include "varia/core/mechanical_field.hpp"
#include "varia/core/mechanics.hpp"
#include "varia/abi/one_step.hpp"

namespace varia {

class OneStepHamiltonianMap : public DiscreteHamiltonianMap {
 public:
  // Throws std::invalid_argument unless the Lagrangian matches the manifold (a vector space or a
  // Lie group) and the field can be formed (lie_group_field.hpp, mechanical_field.hpp).
  OneStepHamiltonianMap(Manifold& manifold, Lagrangian& lagrangian, OneStepMethod& method,
                        SolverOptions options);
  int point_size() const override { return m_; }
  int dim() const override { return n_; }
  // Empty on a vector space with a Lagrangian that evaluates at jets.
  std::string tangent_map_refusal() const override;
 protected:
  void take_step(const double* q0, const double* p0, double t0, double h, double* q1, double* p1) override;
  // The step, then the method's step at first-order jets along the directions: a one-step method
  // steps jets with the exact derivatives of Psi_h (one_step.hpp), which is the implicit function
  // theorem on its stage equations (Runge-Kutta methods commute with linearization). In passes of
  // at most the field's jet_variables() directions.
  void take_tangent_step(const double* q0, const double* p0, double t0, double h, double* q1, double* p1, int count,
                         const double* directions, double* images) override;

 public:
  // The method's stage solves (zeros for explicit methods).
  const SolverStatistics& solver_statistics() const override { return statistics_; }
  const EvaluationCounters& evaluations() const override { return lagrangian_.counters(); }

 private:
  LagrangianEvaluator lagrangian_;
  std::unique_ptr<EulerLagrangeField> field_;
  OneStepMethod& method_;
  int m_, n_;  // point size, dimension
  // The state is (q, xi) with the momenta converted by the Legendre transform where the field is in
  // (q, v) without a constant mass matrix (on a Lie group), with these options.
  bool tangent_;
  SolverOptions options_;
  SolverStatistics statistics_;
  Eigen::VectorXd y0_, y1_;
  std::vector<Jet2> jets0_, jets1_;  // the tangent map's state at jets
  Eigen::VectorXd deviation_w_;      // a direction's w part
  SolverStatistics tangent_stages_;  // the jet steps' stage solves (not the run's)
};

}  // namespace varia
