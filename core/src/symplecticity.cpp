// verification.hpp's symplecticity measurements: the one-step map's derivative in canonical chart
// coordinates by differences (or its tangent map), the defect of the symplectic form on a set of
// directions, and the tangent space of a constraint's cotangent bundle those directions span there.
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>

#include "varia/core/verification.hpp"

namespace varia {

namespace {

// The one-step map in canonical coordinates z = (xi, pi) of T*Q: xi in the natural chart at
// `base`, pi = B^T mu the chart's conjugate momentum, where mu is the (left-trivialized) momentum
// and B = d velocity / d xi_dot = dexp_{-xi} (Manifold::chart; the identity on a vector
// space, where z = (q - base, p)).
class CanonicalChart {
 public:
  CanonicalChart(DiscreteHamiltonianMap& map, Manifold& manifold, const double* base)
      : map_(map), manifold_(manifold), base_(base, base + manifold.point_size()),
        n_(manifold.dim()), q_(manifold.point_size()), q1_(manifold.point_size()), mu_(n_), mu1_(n_),
        B_(n_, n_), velocity_gradient_(2 * n_ * n_) {}
  void step(const Eigen::VectorXd& z, double h, Eigen::VectorXd& out) {
    check(manifold_, manifold_.retract(base_.data(), z.data(), q_.data()), "manifold retract");
    chart_momentum_matrix(z.data());
    mu_ = B_.transpose().partialPivLu().solve(z.tail(n_));
    map_.step(q_.data(), mu_.data(), h, q1_.data(), mu1_.data());
    check(manifold_, manifold_.local(base_.data(), q1_.data(), out.data()), "manifold local");
    chart_momentum_matrix(out.data());
    out.tail(n_) = B_.transpose() * mu1_;
  }

 private:
  void chart_momentum_matrix(const double* xi) {
    if (manifold_.is_vector_space()) {
      B_.setIdentity();
      return;
    }
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n_);
    check(manifold_, manifold_.chart(base_.data(), xi, zero.data(), {}, {nullptr, velocity_gradient_.data(), nullptr}),
          "manifold chart");
    for (int k = 0; k < n_; ++k) B_.row(k) = velocity_gradient_.segment(k * 2 * n_ + n_, n_).transpose();
  }
  DiscreteHamiltonianMap& map_;
  Manifold& manifold_;
  std::vector<double> base_;
  int n_;
  std::vector<double> q_, q1_;
  Eigen::VectorXd mu_, mu1_;
  Eigen::MatrixXd B_;
  Eigen::VectorXd velocity_gradient_;  // d velocity / d (xi, xi_dot), component-major
};

// The one-step map's derivative in canonical chart coordinates at (xi, pi) = (0, p0) along each
// column d_j of `directions` (a difference step), by central differences of factor d_j:
// column j is M d_j.
Eigen::MatrixXd directional(CanonicalChart& chart, const double* p0, int n, double h, const Eigen::MatrixXd& directions,
                            double factor) {
  Eigen::MatrixXd images(2 * n, directions.cols());
  Eigen::VectorXd z = Eigen::VectorXd::Zero(2 * n), plus(2 * n), minus(2 * n);
  for (int i = 0; i < n; ++i) z[n + i] = p0[i];
  for (Eigen::Index j = 0; j < directions.cols(); ++j) {
    chart.step(z + factor * directions.col(j), h, plus);
    chart.step(z - factor * directions.col(j), h, minus);
    images.col(j) = (plus - minus) / (2 * factor);
  }
  return images;
}

// The defect of the symplectic form on the directions D, in the rescaled coordinates S = diag(1/a, a)
// (S is symplectic) with each direction of unit length there: max |(S M D N)^T J (S M D N) -
// (S D N)^T J (S D N)|, N = diag(1 / |S d_j|). With D the coordinate directions it is
// ||(S M S^-1)^T J (S M S^-1) - J||max, zero exactly when M is symplectic; with D a basis of the
// tangent space of a submanifold, zero exactly when M preserves the form restricted to it.
// `scale` (if not null): the largest entry of the rescaled (S M D N)^T J (S M D N), the size of the
// terms the defect is a difference of.
double defect(const Eigen::MatrixXd& images, const Eigen::MatrixXd& directions, const Eigen::VectorXd& a,
              double* scale = nullptr) {
  const int n = static_cast<int>(images.rows()) / 2;
  Eigen::VectorXd s(2 * n);
  s << a.cwiseInverse(), a;
  Eigen::MatrixXd in = s.asDiagonal() * directions, out = s.asDiagonal() * images;
  for (Eigen::Index j = 0; j < in.cols(); ++j) {
    const double length = in.col(j).norm();
    in.col(j) /= length;
    out.col(j) /= length;
  }
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  J.topRightCorner(n, n).setIdentity();
  J.bottomLeftCorner(n, n) = -Eigen::MatrixXd::Identity(n, n);
  const Eigen::MatrixXd form = out.transpose() * J * out;
  if (scale != nullptr) *scale = form.cwiseAbs().maxCoeff();
  return (form - in.transpose() * J * in).cwiseAbs().maxCoeff();
}

}  // namespace

SymplecticityDefect exact_symplecticity_defect(DiscreteHamiltonianMap& map, const double* q0, const double* p0,
                                               double t0, double h, const Eigen::VectorXd& steps, double tolerance) {
  const int n = map.dim();
  const Eigen::VectorXd a = (steps.head(n).array() / steps.tail(n).array()).sqrt();
  const Eigen::MatrixXd directions = steps.asDiagonal();
  Eigen::MatrixXd images(2 * n, 2 * n);
  Eigen::VectorXd q1(map.point_size()), p1(n);
  map.step_with_tangent(q0, p0, t0, h, q1.data(), p1.data(), 2 * n, directions.data(), images.data());
  double scale = 0.0;
  const double value = defect(images, directions, a, &scale);
  constexpr double eps = std::numeric_limits<double>::epsilon();
  return {value, (2 * n * eps + tolerance) * std::max(1.0, scale)};
}

double symplecticity_residual(const Eigen::MatrixXd& M) {
  return defect(M, Eigen::MatrixXd::Identity(M.rows(), M.cols()), Eigen::VectorXd::Ones(M.rows() / 2));
}

SymplecticityDefect symplecticity_defect(DiscreteHamiltonianMap& map, Manifold& manifold,
                                         const double* q0, const double* p0, double h,
                                         const Eigen::VectorXd& steps, const Eigen::MatrixXd& tangent) {
  // Richardson: (4 M(d/2) - M(d)) / 3 cancels the O(d^2) term of central differences.
  const int n = manifold.dim();
  const Eigen::VectorXd a = (steps.head(n).array() / steps.tail(n).array()).sqrt();
  const Eigen::MatrixXd directions = tangent.size() > 0 ? tangent : Eigen::MatrixXd(steps.asDiagonal());
  CanonicalChart chart(map, manifold, q0);
  auto richardson = [&](double factor) {
    return Eigen::MatrixXd(
        (4.0 * directional(chart, p0, n, h, directions, factor / 2) - directional(chart, p0, n, h, directions, factor)) /
        3.0);
  };
  const double coarse = defect(richardson(1.0), directions, a), fine = defect(richardson(0.5), directions, a);
  return {fine, std::abs(fine - coarse) + 1e-13};
}

Eigen::MatrixXd constrained_tangent_basis(HolonomicConstraints& constraints, const Eigen::MatrixXd& mass,
                                          const double* q, const double* p, double position_step, double momentum_step) {
  const int n = constraints.dim(), m = constraints.size();
  constraints.evaluate_jacobian(q);
  const Eigen::MatrixXd G = constraints.jacobian();
  const Eigen::LLT<Eigen::MatrixXd> M(mass);
  const Eigen::VectorXd v = M.solve(Eigen::Map<const Eigen::VectorXd>(p, n));
  Eigen::MatrixXd K(m, n);  // d(G(q) v)/dq at fixed v: row i is (H_i v)^T, H_i the Hessian of g_i
  Eigen::VectorXd unit = Eigen::VectorXd::Zero(m);
  for (int i = 0; i < m; ++i) {
    unit.setZero();
    unit[i] = 1.0;
    constraints.evaluate_hessian(q, unit.data());
    K.row(i) = (constraints.hessian() * v).transpose();
  }
  TangentBasis tangent(constraints);
  const Eigen::MatrixXd Z = tangent.at(q);
  const Eigen::MatrixXd MinvGt = M.solve(G.transpose());
  const Eigen::MatrixXd lift = -G.transpose() * (G * MinvGt).partialPivLu().solve(K * Z);  // dp keeping G M^-1 p = 0
  Eigen::MatrixXd basis = Eigen::MatrixXd::Zero(2 * n, 2 * (n - m));
  basis.topLeftCorner(n, n - m) = position_step * Z;
  basis.bottomLeftCorner(n, n - m) = position_step * lift;
  basis.bottomRightCorner(n, n - m) = momentum_step * (mass * Z);
  return basis;
}

}  // namespace varia
