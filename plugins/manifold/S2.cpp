// S2, the unit vectors of R^3 (spec: "Constrained systems, S2 and products"), a homogeneous space
// of SO(3) acting by rotation. A point is 3 numbers with |q| = 1; velocities and momenta are given
// in the same ambient form, 3 numbers (q . q' = 0, q . p = 0).
//
// The constructions serve S2 in its embedding: it gives its equation as a holonomic constraint
// (Manifold::defining_constraint),
//   g(q) = (|q|^2 - 1) / 2,   G(q) = q^T,   the Hessian of lambda g = lambda I,
// whose multiplier enters the constrained discrete Euler-Lagrange equations (docs/constraints.md).
// Its chart, for the tools that move along the manifold, is the exponential map of the round
// sphere in an orthonormal basis (b1, b2) of the tangent plane at q0 (b1 = e_k x q0 / |e_k x q0|
// with e_k the axis least aligned with q0, b2 = q0 x b1): with u = xi_1 b1 + xi_2 b2,
//   retract: q = cos|u| q0 + sin|u| u / |u|  (the great circle; exp(hat(q0 x u)) q0),
//   local:   u = theta w / |w|,  w = q - (q0 . q) q0,  theta = atan2(|w|, q0 . q),
// defined away from the antipode -q0.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>

#include "varia/abi/constraint.hpp"
#include "varia/abi/manifold.hpp"
#include "varia/sdk/no_parameters.hpp"
#include "varia/sdk/plugin.hpp"

namespace {

using Vector3 = Eigen::Vector3d;

// A point's distance from the sphere |q| = 1 that still counts as on it (spec: initial.q within
// 1e-10).
constexpr double kOnSphere = 1e-10;

// g(q) = (|q|^2 - 1) / 2: one row, G = q^T (3 entries), the Hessian of lambda g = lambda I (3
// diagonal entries).
class UnitNorm final : public varia::Constraint {
 public:
  varia::Status bind(int n, int /*space_dim*/) noexcept override {
    return n == 3 ? nullptr : "S2's equation |q| = 1 binds to the 3 numbers of a point";
  }
  int size() const noexcept override { return 1; }
  int jacobian_pattern(const int** rows, const int** cols) const noexcept override {
    *rows = kRows;
    *cols = kCols;
    return 3;
  }
  int hessian_pattern(const int** rows, const int** cols) const noexcept override {
    *rows = kCols;
    *cols = kCols;
    return 3;
  }
  varia::Status evaluate(const double* q, double* g, double* jacobian) noexcept override {
    if (g != nullptr) g[0] = 0.5 * (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] - 1.0);
    if (jacobian != nullptr) std::copy_n(q, 3, jacobian);
    return nullptr;
  }
  bool quadratic() const noexcept override { return true; }
  varia::Status weighted_hessian(const double* /*q*/, const double* lambda, double* values) noexcept override {
    std::fill_n(values, 3, lambda[0]);
    return nullptr;
  }

 private:
  static constexpr int kRows[3] = {0, 0, 0};
  static constexpr int kCols[3] = {0, 1, 2};
};

// (b1, b2), an orthonormal basis of the tangent plane at the unit vector q0.
void tangent_basis(const Vector3& q0, Vector3& b1, Vector3& b2) {
  Eigen::Index k = 0;
  q0.cwiseAbs().minCoeff(&k);
  b1 = Vector3::Unit(k).cross(q0).normalized();
  b2 = q0.cross(b1);
}

class S2 final : public varia::Manifold {
 public:
  static constexpr const char* version = "1.0.0";
  static constexpr const char* parameter_schema = varia::sdk::kNoParameters;
  static constexpr const char* properties = R"json({
    "group": "SO(3) acting by rotation (a homogeneous space, SO(3)/SO(2))",
    "chart": "the sphere's exponential map (great circles) in a tangent basis at q0",
    "point": "a unit vector, 3 numbers",
    "tangent": "ambient, 3 numbers orthogonal to the point",
    "served": "in its embedding: the equation (|q|^2 - 1)/2 = 0 with its multiplier"
  })json";

  S2(const nlohmann::json& parameters, const varia::sdk::Context&) {
    varia::sdk::require_no_parameters(parameters, "S2");
  }

  int point_size() const noexcept override { return 3; }
  int dim() const noexcept override { return 2; }
  varia::ManifoldStructure structure() const noexcept override {
    return varia::ManifoldStructure::homogeneous_space;
  }
  varia::Constraint* defining_constraint() noexcept override { return &unit_norm_; }

  varia::Status retract(const double* q0, const double* xi, double* q) noexcept override {
    Vector3 b1, b2;
    const Vector3 p0(q0[0], q0[1], q0[2]);
    tangent_basis(p0, b1, b2);
    const Vector3 u = xi[0] * b1 + xi[1] * b2;
    const double theta = u.norm();
    const Vector3 moved = std::cos(theta) * p0 + (theta > 0 ? std::sin(theta) / theta : 1.0) * u;
    std::copy_n(moved.data(), 3, q);
    return nullptr;
  }
  varia::Status local(const double* q0, const double* q, double* xi) noexcept override {
    Vector3 b1, b2;
    const Vector3 p0(q0[0], q0[1], q0[2]), p(q[0], q[1], q[2]);
    tangent_basis(p0, b1, b2);
    const double along = p0.dot(p);
    const Vector3 w = p - along * p0;
    const double width = w.norm();
    if (width == 0.0 && along < 0) return "S2: the chart at q0 does not reach its antipode -q0";
    const double theta = std::atan2(width, along);
    const Vector3 u = width > 0 ? Vector3(theta / width * w) : Vector3::Zero();
    xi[0] = u.dot(b1);
    xi[1] = u.dot(b2);
    return nullptr;
  }
  bool contains(const double* q, char* why, int why_size) noexcept override {
    const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
    if (std::abs(norm - 1.0) <= kOnSphere) return true;
    if (why != nullptr && why_size > 0)
      std::snprintf(why, static_cast<std::size_t>(why_size), "expected a unit vector (| |q| - 1 | <= %g); |q| = %.17g",
                    kOnSphere, norm);
    return false;
  }

 private:
  UnitNorm unit_norm_;
};

}  // namespace

VARIA_PLUGIN(S2, manifold, S2)
