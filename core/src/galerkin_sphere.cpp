// The Galerkin construction on products of S2 in the natural chart at q0 (galerkin_sphere.hpp: the
// chart, L_d, and D1 L_d from the balance of angular momentum).
#include "varia/core/galerkin_sphere.hpp"
#include "varia/core/so3.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace varia {

namespace {

// The exponential map's coefficients as functions of x = |w|^2, smooth through x = 0:
// C(x) = cos(sqrt x) and S(x) = sin(sqrt x) / sqrt x with S's derivatives S1..S3 in x (C' = -S/2,
// C'' = -S1/2). Below x = 1 their Taylor series to x^12 (the next terms below 1e-19 of the sums);
// above, the closed forms, S1 = (C - S) / (2x) and S(m+1) = (-S(m-1)/2 - (2m+1) S(m)) / (2x).
struct ExponentialCoefficients {
  double C, S[4];
};

ExponentialCoefficients exponential_coefficients(double x) {
  ExponentialCoefficients r{};
  if (x < 1.0) {
    constexpr int kTerms = 13;
    double cosine = 0.0, factorial = 1.0, power = 1.0;  // (2k)!, x^k
    double a[kTerms];                                    // S's coefficients (-1)^k / (2k+1)!
    for (int k = 0; k < kTerms; ++k) {
      if (k > 0) factorial *= (2.0 * k - 1) * (2.0 * k);
      cosine += (k % 2 == 0 ? 1.0 : -1.0) * power / factorial;
      a[k] = (k % 2 == 0 ? 1.0 : -1.0) / (factorial * (2.0 * k + 1));
      power *= x;
    }
    r.C = cosine;
    for (int m = 0; m < 4; ++m) {  // S^(m)(x) = sum_k a_k k!/(k-m)! x^(k-m), by Horner
      double sum = 0.0;
      for (int k = kTerms - 1; k >= m; --k) {
        double falling = 1.0;
        for (int j = 0; j < m; ++j) falling *= k - j;
        sum = sum * x + a[k] * falling;
      }
      r.S[m] = sum;
    }
    return r;
  }
  const double root = std::sqrt(x);
  r.C = std::cos(root);
  r.S[0] = std::sin(root) / root;
  r.S[1] = (r.C - r.S[0]) / (2 * x);
  for (int m = 1; m < 3; ++m) r.S[m + 1] = (-r.S[m - 1] / 2 - (2 * m + 1) * r.S[m]) / (2 * x);
  return r;
}

// C, S and S1 at x, a double or a jet (each a function of one variable: jet::unary).
void exponential_coefficients(double x, double& C, double& S, double& dS) {
  const ExponentialCoefficients r = exponential_coefficients(x);
  C = r.C, S = r.S[0], dS = r.S[1];
}
void exponential_coefficients(const Jet2& x, Jet2& C, Jet2& S, Jet2& dS) {
  const ExponentialCoefficients r = exponential_coefficients(x.value);
  C = jet::unary(x, r.C, -r.S[0] / 2, -r.S[1] / 2);
  S = jet::unary(x, r.S[0], r.S[1], r.S[2]);
  dS = jet::unary(x, r.S[1], r.S[2], r.S[3]);
}

// An orthonormal basis (e1, e2) of T_q S2 = q^perp: e1 along a x q, a the coordinate axis least
// aligned with q, and e2 = q x e1.
void tangent_basis(const double* q, double* first, double* second) {
  const Eigen::Map<const Eigen::Vector3d> n(q);
  Eigen::Index axis;
  n.cwiseAbs().minCoeff(&axis);
  const Eigen::Vector3d e1 = Eigen::Vector3d::Unit(axis).cross(n).normalized();
  Eigen::Map<Eigen::Vector3d> out1(first), out2(second);
  out1 = e1;
  out2 = n.cross(e1);
}

// r += a x b (3-vectors of jets).
void add_cross(const Jet2* a, const Jet2* b, double scale, Jet2* r) {
  for (int c = 0; c < 3; ++c) {
    const int i = (c + 1) % 3, j = (c + 2) % 3;
    add_scaled(r[c], scale, a[i] * b[j] - a[j] * b[i]);
  }
}

}  // namespace

// The step's equations as a NewtonSolver system: F = (dA/dw^1, .., dA/dw^(s-1), the balance in
// T_{q0}), in the unknowns w^1..w^s (unknowns_, 2N x s).
struct SphereGalerkinMap::Equations {
  SphereGalerkinMap& g;
  const double* q0;
  const double* p0;
  double h;
  bool interior_only = false;  // L_d's equations: dA/dw^j = 0 (j < s) in w^1..w^(s-1), w^s fixed

  int size() const { return static_cast<int>(g.unknowns_.size()) - (interior_only ? 2 * g.spheres_count_ : 0); }
  DenseLinearization& linearization() const { return interior_only ? g.interior_linearization_ : g.linearization_; }

  double evaluate(Eigen::Ref<Eigen::VectorXd> F) {
    const Jet2 action = action_at_jets();
    const int interior = static_cast<int>(g.unknowns_.size()) - 2 * g.spheres_count_, n = size();
    auto& J = linearization().jacobian;
    for (int k = 0; k < interior; ++k) {
      F[k] = action.gradient[k];
      J.row(k) = action.hessian.row(k).head(n);
    }
    double yardstick = action.gradient.lpNorm<Eigen::Infinity>();
    if (!interior_only)
      for (int a = 0; a < g.spheres_count_; ++a) yardstick = std::max(yardstick, add_balance(a, action, F));
    return yardstick;
  }
  void factorize() { linearization().factorize(); }
  void solve(const Eigen::VectorXd& F, Eigen::VectorXd& update) { linearization().solve(F, update); }
  double apply(const Eigen::VectorXd& update) {
    g.unknowns_.reshaped().head(size()) -= update;
    return 1.0;  // the points, on unit spheres
  }
  // p1 brought to the last update to first order (its Jacobian at hand).
  void finish(const Eigen::VectorXd& update) {
    if (!interior_only)
      for (Jet2& p : g.end_momentum_) p.value -= p.gradient.dot(update);
  }

  // A = h sum_i b_i L(q(c_i h), q'(c_i h)) at jets in all 2 N s unknowns, and the balance's
  // tau = h sum_i b_i (q_i x L_q + q_i' x L_v) and its first derivatives into g.balance_value_ and
  // g.balance_jacobian_. The node's z = (q, q') is a jet of
  // the chart alone; L's gradient and Hessian at z's value give A's by the chain rule,
  // A_W += b (J^T grad L), A_WW += b (J^T H J + sum_r (grad L)_r z_r's Hessian), J = dz/dW, and
  // grad L's first derivatives H J (L is not evaluated at jets: its Hessian at doubles costs less).
  Jet2 action_at_jets() {
    const int N = g.spheres_count_, D = static_cast<int>(g.unknowns_.size()), k = 6 * N;
    for (int j = 0; j < D; ++j) g.variables_[j] = Jet2::variable(g.unknowns_.data()[j], D, j);
    Jet2 action(0.0);
    action.resize(D);
    action.gradient.setZero();
    action.hessian.setZero();
    g.balance_value_.setZero();
    g.balance_jacobian_.setZero();
    for (int i = 0; i < g.weights_.size(); ++i) {
      for (int a = 0; a < N; ++a) curve_at(i, a);
      for (int r = 0; r < k; ++r) {
        const Jet2& z = r < 3 * N ? g.q_[r] : g.v_[r - 3 * N];
        g.node_point_[r] = z.value;
        if (z.constant()) g.node_jacobian_.row(r).setZero();
        else g.node_jacobian_.row(r) = z.gradient.transpose();
      }
      const double w = h * g.weights_[i];
      action.value += w * g.lagrangian_.hessian(g.node_point_.data(), g.node_point_.data() + 3 * N,
                                               g.node_gradient_.data(), g.node_hessian_.data());
      g.node_product_.noalias() = g.node_hessian_ * g.node_jacobian_;
      action.gradient.noalias() += w * (g.node_jacobian_.transpose() * g.node_gradient_);
      action.hessian.noalias() += w * (g.node_jacobian_.transpose() * g.node_product_);
      for (int r = 0; r < k; ++r) {
        const Jet2& z = r < 3 * N ? g.q_[r] : g.v_[r - 3 * N];
        if (!z.constant()) action.hessian += (w * g.node_gradient_[r]) * z.hessian;
      }
      for (int a = 0; a < N; ++a) {
        add_balance_terms(w, 3 * a, 3 * a);
        add_balance_terms(w, 3 * a, 3 * N + 3 * a);
      }
    }
    return action;
  }
  // tau's terms w z x (grad L)_z of the rows `at` of z (q_a or q_a'), and their derivatives in W,
  // d(z x y) = -[y]x dz + [z]x dy, dz = J, dy = H J, into factor a's rows `first` of the balance.
  void add_balance_terms(double w, int first, int at) {
    const Eigen::Vector3d z = g.node_point_.segment<3>(at), y = g.node_gradient_.segment<3>(at);
    g.balance_value_.segment<3>(first) += w * z.cross(y);
    g.balance_jacobian_.middleRows<3>(first).noalias() +=
        (w * so3::hat(z)) * g.node_product_.middleRows<3>(at) - (w * so3::hat(y)) * g.node_jacobian_.middleRows<3>(at);
  }

  // Factor a's point and velocity on the curve at node i, as jets in the unknowns, into q_, v_.
  void curve_at(int i, int a) {
    const int N = g.spheres_count_, s = g.degree(), block = 2 * N;
    Jet2 w[2] = {Jet2(0.0), Jet2(0.0)}, wd[2] = {Jet2(0.0), Jet2(0.0)};
    for (int j = 1; j <= s; ++j)
      for (int k = 0; k < 2; ++k) {
        const Jet2& x = g.variables_[(j - 1) * block + 2 * a + k];
        add_scaled(w[k], g.basis_.phi(j, i), x);
        add_scaled(wd[k], g.basis_.dphi(j, i) / h, x);
      }
    point_and_velocity(a, w, wd, &g.q_[3 * a], &g.v_[3 * a]);
  }
  // q = Exp_{q0}(w) and its derivative along w' (3 jets each).
  void point_and_velocity(int a, const Jet2* w, const Jet2* wd, Jet2* q, Jet2* v) const {
    Jet2 C, S, dS;
    exponential_coefficients(w[0] * w[0] + w[1] * w[1], C, S, dS);
    const Jet2 twice_rate = 2.0 * (w[0] * wd[0] + w[1] * wd[1]);
    const double* base = q0 + 3 * a;
    for (int c = 0; c < 3; ++c) {
      const double e1 = g.bases_(c, 2 * a), e2 = g.bases_(c, 2 * a + 1);
      const Jet2 Ew = e1 * w[0] + e2 * w[1], Ewd = e1 * wd[0] + e2 * wd[1];
      q[c] = C * base[c] + S * Ew;
      v[c] = twice_rate * (-0.5 * S * base[c] + dS * Ew) + S * Ewd;
    }
  }
  // Factor a's rows of the balance, e_k . (q0 x p0 - q1 x p1 + tau), with p1 = Dphi (Dphi^T Dphi)^-1 pi
  // and pi = dA/dw^s (a jet of first order from A's Hessian). Returns the terms' size.
  double add_balance(int a, const Jet2& action, Eigen::Ref<Eigen::VectorXd> F) {
    const int N = g.spheres_count_, s = g.degree(), D = size(), first = (s - 1) * 2 * N + 2 * a;
    const Jet2* w = &g.variables_[first];
    Jet2 columns[2][3], pi[2];
    Jet2* q1 = &g.end_point_[3 * a];
    for (int k = 0; k < 2; ++k) {
      const Jet2 unit[2] = {Jet2(k == 0 ? 1.0 : 0.0), Jet2(k == 1 ? 1.0 : 0.0)};
      point_and_velocity(a, w, unit, q1, columns[k]);  // q1, and Dphi e_k as the velocity along e_k
      pi[k] = Jet2(action.gradient[first + k]);
      pi[k].resize(D);
      pi[k].gradient = action.hessian.row(first + k).transpose();
      pi[k].hessian.setZero();
    }
    const Jet2 g00 = dot(columns[0], columns[0]), g01 = dot(columns[0], columns[1]), g11 = dot(columns[1], columns[1]);
    const Jet2 det = g00 * g11 - g01 * g01;
    const Jet2 c0 = (g11 * pi[0] - g01 * pi[1]) / det, c1 = (g00 * pi[1] - g01 * pi[0]) / det;
    Jet2* p1 = &g.end_momentum_[3 * a];
    for (int c = 0; c < 3; ++c) p1[c] = columns[0][c] * c0 + columns[1][c] * c1;
    Jet2 m[3];
    const double* base = q0 + 3 * a;
    const double* momentum = p0 + 3 * a;
    double size = 0.0;
    for (int c = 0; c < 3; ++c) {
      const int i = (c + 1) % 3, j = (c + 2) % 3, row = 3 * a + c;
      const double tau = g.balance_value_[row], angular = base[i] * momentum[j] - base[j] * momentum[i];
      m[c] = Jet2(tau + angular);
      m[c].resize(D);
      m[c].gradient = g.balance_jacobian_.row(row).transpose();
      m[c].hessian.setZero();
      size = std::max({size, std::abs(tau), std::abs(angular)});
    }
    add_cross(q1, p1, -1.0, m);
    for (int c = 0; c < 3; ++c) g.balance_residual_[3 * a + c] = m[c].value;
    auto& J = g.linearization_.jacobian;
    for (int k = 0; k < 2; ++k) {
      Jet2 row(0.0);
      for (int c = 0; c < 3; ++c) add_scaled(row, g.bases_(c, 2 * a + k), m[c]);
      F[first + k] = row.value;
      J.row(first + k) = row.gradient.transpose();
    }
    return size;
  }
  static Jet2 dot(const Jet2* a, const Jet2* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
};

SphereGalerkinMap::SphereGalerkinMap(Lagrangian& lagrangian, Quadrature& quadrature, std::vector<double> control_times,
                                     SolverOptions options, HolonomicConstraints& spheres)
    : lagrangian_(lagrangian),
      basis_(control_times, quadrature),
      weights_(Eigen::Map<const Eigen::VectorXd>(quadrature.weights(), quadrature.size())),
      spheres_count_(spheres.size()),
      projection_(spheres, [&] {
        if (spheres.dim() != 3 * spheres.size())
          throw std::invalid_argument("the natural chart of S2 takes N spheres' equations on R^(3N)");
        Eigen::VectorXd q = Eigen::VectorXd::Zero(spheres.dim());
        for (int a = 0; a < spheres.size(); ++a) q[3 * a + 2] = 1.0;
        return constant_mass_entries(lagrangian_, q.data());
      }()),
      solver_(options),
      interior_solver_(options) {
  const int D = unknowns(spheres_count_, degree());
  if (quadrature.derivative_terms() > 0)
    throw std::invalid_argument("Galerkin in the natural chart of S2 takes quadrature rules without derivative terms");
  if (D > kMaxJetVariables)
    throw std::invalid_argument("Galerkin in the natural chart of S2 takes at most " + std::to_string(kMaxJetVariables) +
                                " unknowns a step (2 N s), got " + std::to_string(D));
  linearization_ = DenseLinearization(D);
  interior_linearization_ = DenseLinearization(D - 2 * spheres_count_);
  bases_.resize(3, 2 * spheres_count_);
  unknowns_.resize(2 * spheres_count_, degree());
  variables_.resize(D);
  q_.resize(3 * spheres_count_);
  v_.resize(3 * spheres_count_);
  node_point_.resize(6 * spheres_count_);
  node_gradient_.resize(6 * spheres_count_);
  node_hessian_.resize(6 * spheres_count_, 6 * spheres_count_);
  node_jacobian_.resize(6 * spheres_count_, D);
  node_product_.resize(6 * spheres_count_, D);
  balance_value_.resize(3 * spheres_count_);
  balance_jacobian_.resize(3 * spheres_count_, D);
  end_point_.resize(3 * spheres_count_);
  end_momentum_.resize(3 * spheres_count_);
  correction_.resize(3 * spheres_count_);
  no_momentum_ = Eigen::VectorXd::Zero(3 * spheres_count_);
  balance_residual_.resize(3 * spheres_count_);
  base_.resize(3 * spheres_count_);
  end_.resize(3 * spheres_count_);
}

SphereGalerkinMap::~SphereGalerkinMap() = default;

// From the velocity of (q0, p0) (the projection's M^-1 p), w^j = d_j h v0 in each tangent plane;
// Newton on the equations; q1 = Exp_{q0}(w^s) and p1 in the constructions' form.
void SphereGalerkinMap::take_step(const double* q0, const double* p0, double /*t0*/, double h, double* q1, double* p1) {
  const int N = spheres_count_, s = degree();
  set_bases(q0);
  projection_.correction(q0, p0, correction_.data());
  const Eigen::VectorXd& v0 = projection_.velocity();
  for (int a = 0; a < N; ++a) {
    const Eigen::Matrix<double, 3, 2> E = bases_.middleCols<2>(2 * a);  // (fixed sizes: nothing allocated)
    const Eigen::Vector2d velocity = E.transpose() * v0.segment<3>(3 * a);
    for (int j = 1; j <= s; ++j) unknowns_.col(j - 1).segment<2>(2 * a) = (basis_.control_times[j] * h) * velocity;
  }
  Equations equations{*this, q0, p0, h};
  require_converged(solver_.solve(equations, statistics_), "the Galerkin equations in the natural chart of S2");
  for (int a = 0; a < N; ++a) {
    const Eigen::Vector2d w = unknowns_.col(s - 1).segment<2>(2 * a);
    const Eigen::Matrix<double, 3, 2> E = bases_.middleCols<2>(2 * a);
    double C, S, dS;
    exponential_coefficients(w.squaredNorm(), C, S, dS);
    Eigen::Map<Eigen::Vector3d>(q1 + 3 * a) = C * Eigen::Map<const Eigen::Vector3d>(q0 + 3 * a) + S * (E * w);
  }
  for (int k = 0; k < 3 * N; ++k) p1[k] = end_momentum_[k].value;
  projection_.correction(q1, p1, correction_.data());
  Eigen::Map<Eigen::VectorXd>(p1, 3 * N) += correction_;
}

void SphereGalerkinMap::set_bases(const double* q0) {
  for (int a = 0; a < spheres_count_; ++a) tangent_basis(q0 + 3 * a, &bases_(0, 2 * a), &bases_(0, 2 * a + 1));
}

// w^s = Log_{q0}(q1) = theta (q1 - cos(theta) q0) / sin(theta) on each factor, the internal points
// from the geodesic (w^j = d_j w^s), then Newton on dA/dw^j = 0; at the solution D2 = p1 and, from
// the balance with p0 = 0 (m = tau - q1 x p1 = -q0 x p0), D1 = -p0 = m x q0.
void SphereGalerkinMap::evaluate(const double* point0, const double* point1, double h, double* Ld, double* D1,
                                 double* D2) {
  const int N = spheres_count_, s = degree();
  for (int a = 0; a < N; ++a) {  // (points off the spheres are taken onto them radially)
    base_.segment<3>(3 * a) = Eigen::Map<const Eigen::Vector3d>(point0 + 3 * a).normalized();
    end_.segment<3>(3 * a) = Eigen::Map<const Eigen::Vector3d>(point1 + 3 * a).normalized();
  }
  const double *q0 = base_.data(), *q1 = end_.data();
  set_bases(q0);
  for (int a = 0; a < N; ++a) {
    const Eigen::Map<const Eigen::Vector3d> x0(q0 + 3 * a), x1(q1 + 3 * a);
    const double c = x0.dot(x1), theta = std::atan2(x0.cross(x1).norm(), c);
    const double scale = theta < 1e-8 ? 1.0 + theta * theta / 6 : theta / std::sin(theta);
    const Eigen::Matrix<double, 3, 2> E = bases_.middleCols<2>(2 * a);
    const Eigen::Vector2d w = scale * (E.transpose() * (x1 - c * x0));
    for (int j = 1; j <= s; ++j) unknowns_.col(j - 1).segment(2 * a, 2) = basis_.control_times[j] * w;
  }
  Equations interior{*this, q0, no_momentum_.data(), h, true};
  if (s > 1)
    require_converged(interior_solver_.solve(interior, interior_statistics_),
                      "the internal points' equations of L_d in the natural chart of S2");
  Equations full{*this, q0, no_momentum_.data(), h};
  Eigen::VectorXd F(unknowns_.size());
  const Jet2 action = full.action_at_jets();
  if (Ld != nullptr) *Ld = action.value;
  for (int a = 0; a < N; ++a) full.add_balance(a, action, F);
  for (int a = 0; a < N; ++a) {
    const Eigen::Map<const Eigen::Vector3d> m(balance_residual_.data() + 3 * a), x0(q0 + 3 * a);
    if (D1 != nullptr) Eigen::Map<Eigen::Vector3d>(D1 + 3 * a) = m.cross(x0);
    if (D2 != nullptr)
      for (int c = 0; c < 3; ++c) D2[3 * a + c] = end_momentum_[3 * a + c].value;
  }
}

}  // namespace varia
