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
 protected:
  void take_step(const double* q0, const double* p0, double t0, double h, double* q1, double* p1) override;

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
};

}  // namespace varia
