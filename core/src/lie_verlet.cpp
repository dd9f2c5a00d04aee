#include "varia/core/lie_verlet.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "varia/core/compensated.hpp"
#include "varia/core/so3.hpp"

namespace varia {

namespace {

using so3::from_row_major;
using so3::hat;
using so3::to_row_major;
using so3::vee;

std::string too_far(double h_omega) {
  return "the Lie group velocity Verlet step turns the body too far: F J_d - J_d F^T = hat(g) has "
         "no solution on the branch through F = I (h |Omega| = " +
         std::to_string(h_omega) +
         "; a spin about a principal axis needs h |Omega| < 1): take a smaller step";
}

}  // namespace

LieGroupVelocityVerlet::LieGroupVelocityVerlet(Manifold& manifold, Lagrangian& lagrangian,
                                               LieVerletSolver solver, SolverOptions options)
    : lagrangian_(lagrangian), solver_(solver), options_(options), newton_(options) {
  if (manifold.point_size() != 9 || manifold.dim() != 3 || manifold.is_vector_space())
    throw std::invalid_argument("the lie-verlet construction needs the manifold SO3");
  if (lagrangian.position_size() != 9 || lagrangian.velocity_size() != 3)
    throw std::invalid_argument(
        "the lie-verlet construction needs a Lagrangian of (R, Omega), 9 + 3 numbers");
  if (!lagrangian.constant_mass_matrix(J_.data()))
    throw std::invalid_argument(
        "the lie-verlet construction needs a Lagrangian of rigid-body form 1/2 Omega . J Omega - "
        "V(R), with a constant inertia J (constant_mass_matrix)");
  Jd_ = 0.5 * J_.trace() * Eigen::Matrix3d::Identity() - J_;  // J = tr(J_d) I - J_d
  reference_determinant_ = (solver_ == LieVerletSolver::cayley ? -2.0 : 1.0) * J_.determinant();
}

double LieGroupVelocityVerlet::trace_product(const Eigen::Matrix3d& D) const {
  return (D * Jd_).trace();
}

// F J_d - J_d F^T = D J_d - J_d D^T for F = I + D: the identity's terms cancel exactly.
Eigen::Vector3d LieGroupVelocityVerlet::skew_part(const Eigen::Matrix3d& D) const {
  const Eigen::Matrix3d X = D * Jd_;
  return vee(Eigen::Matrix3d(X - X.transpose()));
}

// Cayley (paper, eq. Gc): G_c(f) = g + g x f + (g.f) f - 2 J f = 0, with the Jacobian
//   hat(g) + (g.f) I + f g^T - 2 J.
// Exponential (paper, eq. rodc and G): r(f) = vee(F J_d - J_d F^T) - g with F = exp(f), which is
// G(f) - g, G(f) = sinc J f + cosc f x J f. Its Jacobian follows from dF = F hat(dexp(-f) df):
//   dG = K dexp(-f),  K e_a = vee(X_a - X_a^T),  X_a = F hat(e_a) J_d.
void LieGroupVelocityVerlet::residual(const Eigen::Vector3d& f, const Eigen::Vector3d& g,
                                      Eigen::Vector3d& r, Eigen::Matrix3d& jacobian,
                                      Eigen::Matrix3d& D) const {
  if (solver_ == LieVerletSolver::cayley) {
    const double gf = g.dot(f);
    r = g + g.cross(f) + gf * f - 2.0 * J_ * f;
    jacobian = hat(g) + gf * Eigen::Matrix3d::Identity() + f * g.transpose() - 2.0 * J_;
    D = so3::cayley_minus_identity(f);
    return;
  }
  D = so3::expm1(f);
  r = skew_part(D) - g;
  jacobian = skew_part_derivative(Eigen::Matrix3d(Eigen::Matrix3d::Identity() + D)) * so3::dexp(Eigen::Vector3d(-f));
}

// K with K e_a = vee(X_a - X_a^T), X_a = F hat(e_a) J_d: vee(F J_d - J_d F^T) differentiated along
// F exp(e hat(e_a)).
Eigen::Matrix3d LieGroupVelocityVerlet::skew_part_derivative(const Eigen::Matrix3d& F) const {
  Eigen::Matrix3d K;
  for (int a = 0; a < 3; ++a) {
    const Eigen::Matrix3d X = F * hat(Eigen::Vector3d(Eigen::Vector3d::Unit(a))) * Jd_;
    K.col(a) = vee(Eigen::Matrix3d(X - X.transpose()));
  }
  return K;
}

// The equation for f as a system for NewtonSolver (solve/newton.hpp), with the exact Jacobian.
struct LieGroupVelocityVerlet::Equation {
  LieGroupVelocityVerlet& lgvi;
  const Eigen::Vector3d& g;
  Eigen::Matrix3d jacobian, D;
  Eigen::PartialPivLU<Eigen::Matrix3d> lu;

  int size() const { return 3; }
  // F's round-off yardstick: g, of the size of its terms (g and 2 J f, or F J_d - J_d F^T).
  double evaluate(Eigen::Ref<Eigen::VectorXd> F) {
    Eigen::Vector3d r;
    lgvi.residual(lgvi.f_, g, r, jacobian, D);
    F = r;
    return g.lpNorm<Eigen::Infinity>();
  }
  void factorize() { lu.compute(jacobian); }
  void solve(const Eigen::VectorXd& F, Eigen::VectorXd& update) { update = lu.solve(Eigen::Vector3d(F)); }
  double apply(const Eigen::VectorXd& update) {
    lgvi.f_ -= update;
    return lgvi.f_.lpNorm<Eigen::Infinity>();
  }
  // F - I at the updated f (no plugin call).
  void finish(const Eigen::VectorXd&) {
    D = lgvi.solver_ == LieVerletSolver::cayley ? so3::cayley_minus_identity(lgvi.f_) : so3::expm1(lgvi.f_);
  }
};

// Newton's method from the previous step's f (or from the linearization f = J^{-1} g, halved for
// Cayley). A root whose Jacobian determinant has the other sign than at the identity lies past
// the fold.
Eigen::Matrix3d LieGroupVelocityVerlet::solve(const Eigen::Vector3d& g) {
  const Eigen::Vector3d linear = J_.partialPivLu().solve(g);  // h Omega, to first order
  if (!has_f_) f_ = solver_ == LieVerletSolver::cayley ? Eigen::Vector3d(0.5 * linear) : linear;
  Equation equation{*this, g, {}, {}, {}};
  const SolveReport report = newton_.solve(equation, statistics_);
  if (report.converged() && equation.jacobian.determinant() * reference_determinant_ > 0.0) {
    has_f_ = true;
    return equation.D;
  }
  has_f_ = false;
  throw NumericalFailure(too_far(linear.norm()), report.residual);
}

Eigen::Vector3d LieGroupVelocityVerlet::torque(const Eigen::Matrix3d& R) {
  double q[9];
  const double omega[3] = {0.0, 0.0, 0.0};
  to_row_major(R, q);
  lagrangian_.gradient(q, omega, gradient_.data());
  return so3::trivialize(R, from_row_major(gradient_.data()));
}

void LieGroupVelocityVerlet::take_step(const double* q0, const double* p0, double /*t0*/, double h, double* q1,
                                       double* p1) {
  const bool continuing = has_last_ && h == last_h_ &&
                          std::equal(q0, q0 + 9, last_state_.begin()) &&
                          std::equal(p0, p0 + 3, last_state_.begin() + 9);
  Eigen::Matrix3d R = from_row_major(q0);
  Eigen::Vector3d Pi(p0[0], p0[1], p0[2]);
  if (!continuing) {
    carry_R_.setZero();
    carry_p_.setZero();
    last_torque_ = torque(R);
  }
  has_last_ = false;
  const Eigen::Vector3d half_kick = Pi + 0.5 * h * last_torque_;
  const Eigen::Matrix3d D = solve(h * half_kick);  // F - I
  compensated_add(R, Eigen::Matrix3d(R * D), carry_R_);
  const Eigen::Vector3d M1 = torque(R);
  // Pi_{k+1} - Pi_k = (F - I)^T (Pi_k + h/2 M_k) + h/2 (M_k + M_{k+1}).
  compensated_add(Pi, Eigen::Vector3d(D.transpose() * half_kick + 0.5 * h * (last_torque_ + M1)),
                  carry_p_);
  to_row_major(R, q1);
  for (int i = 0; i < 3; ++i) p1[i] = Pi(i);
  std::copy(q1, q1 + 9, last_state_.begin());
  std::copy(p1, p1 + 3, last_state_.begin() + 9);
  last_torque_ = M1;
  last_h_ = h;
  has_last_ = true;
}

void LieGroupVelocityVerlet::linearize_torque(const Eigen::Matrix3d& R, TorqueLinearization& at) {
  double q[9];
  const double omega[3] = {0.0, 0.0, 0.0};
  to_row_major(R, q);
  at.R = R;
  lagrangian_.hessian(q, omega, gradient_.data(), at.hessian.data());
  at.gradient = from_row_major(gradient_.data());
}

Eigen::Vector3d LieGroupVelocityVerlet::torque_derivative(const TorqueLinearization& at, const Eigen::Vector3d& delta) {
  const Eigen::Matrix3d dR = at.R * hat(delta);
  Eigen::Matrix<double, 9, 1> dq, dG;  // row-major, as q
  to_row_major(dR, dq.data());
  dG.noalias() = at.hessian.topLeftCorner<9, 9>() * dq;
  return Eigen::Vector3d(so3::trivialize(dR, at.gradient) + so3::trivialize(at.R, from_row_major(dG.data())));
}

void LieGroupVelocityVerlet::take_tangent_step(const double* q0, const double* p0, double t0, double h, double* q1,
                                               double* p1, int count, const double* directions, double* images) {
  take_step(q0, p0, t0, h, q1, p1);
  TorqueLinearization start = tangent_end_;  // the last tangent step's end, where this one continues it
  if (!(has_tangent_end_ && start.R == from_row_major(q0))) linearize_torque(from_row_major(q0), start);
  TorqueLinearization& end = tangent_end_;
  linearize_torque(from_row_major(q1), end);
  has_tangent_end_ = true;
  const Eigen::Vector3d Pi0(p0[0], p0[1], p0[2]);
  const Eigen::Vector3d half_kick = Pi0 + 0.5 * h * so3::trivialize(start.R, start.gradient);
  const Eigen::Matrix3d F = start.R.transpose() * end.R;
  const Eigen::PartialPivLU<Eigen::Matrix3d> lu(skew_part_derivative(F));
  const Eigen::Vector3d kicked = F.transpose() * half_kick;
  for (int j = 0; j < count; ++j) {
    const Eigen::Map<const Eigen::Vector3d> delta0(directions + 6 * j), dPi0(directions + 6 * j + 3);
    Eigen::Map<Eigen::Vector3d> delta1(images + 6 * j), dPi1(images + 6 * j + 3);
    const Eigen::Vector3d dM0 = torque_derivative(start, delta0);
    const Eigen::Vector3d phi = lu.solve(Eigen::Vector3d(h * dPi0 + 0.5 * h * h * dM0));
    delta1 = F.transpose() * delta0 + phi;
    dPi1 = -phi.cross(kicked) + F.transpose() * (dPi0 + 0.5 * h * dM0) + 0.5 * h * torque_derivative(end, delta1);
  }
}

// L_d = (1/h) tr((I - F) J_d) + h/2 (L(R0, 0) + L(R1, 0)), and with R0 -> R0 exp(eps eta),
// R1 -> R1 exp(eps eta) (left-trivialized derivatives):
//   D1 L_d = (1/h) vee(J_d F^T - F J_d) + h/2 M0,   D2 L_d = (1/h) vee(J_d F - F^T J_d) + h/2 M1.
void LieGroupVelocityVerlet::evaluate(const double* q0, const double* q1, double h, double* Ld,
                                      double* D1, double* D2) {
  const Eigen::Matrix3d R0 = from_row_major(q0), R1 = from_row_major(q1);
  const Eigen::Matrix3d D = R0.transpose() * R1 - Eigen::Matrix3d::Identity();
  const double omega[3] = {0.0, 0.0, 0.0};
  if (Ld != nullptr)
    *Ld = -trace_product(D) / h +
          0.5 * h * (lagrangian_.value(q0, omega) + lagrangian_.value(q1, omega));
  if (D1 != nullptr) {
    const Eigen::Vector3d d1 = -skew_part(D) / h + 0.5 * h * torque(R0);
    for (int i = 0; i < 3; ++i) D1[i] = d1(i);
  }
  if (D2 != nullptr) {
    const Eigen::Vector3d d2 = -skew_part(Eigen::Matrix3d(D.transpose())) / h + 0.5 * h * torque(R1);
    for (int i = 0; i < 3; ++i) D2[i] = d2(i);
  }
}

}  // namespace varia
