// SE(3), the rigid motions of R^3, as a manifold: a point g = (R, x) is a rotation matrix R
// (9 numbers, row-major) then a position x (3 numbers), acting as y -> R y + x; tangent vectors,
// velocities and momenta are left-trivialized, 6 numbers: g^{-1} g' = (Omega, R^T x') with
// R' = R hat(Omega). The natural chart at g0 (paper, sec. 2, "Natural charts") is g0 exp(xi),
// with the group's exponential
//   exp(w, rho) = (exp(w), dexp_w rho),   log(R, x) = (w, dexp_w^{-1} x), w = log R,
// (dexp_w = I + (1 - cos t)/t^2 hat w + (t - sin t)/t^3 hat w^2, t = |w|: SO(3)'s left Jacobian,
// varia/core/so3.hpp) and the bracket [(w1, v1), (w2, v2)] = (w1 x w2, w1 x v2 - w2 x v1). The
// SDK's adapter (varia/sdk/lie_group.hpp) derives the chart's derivatives from these.
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <cmath>

#include "varia/core/so3.hpp"
#include "varia/sdk/groups/so3.hpp"
#include "varia/sdk/lie_group.hpp"
#include "varia/sdk/no_parameters.hpp"
#include "varia/sdk/plugin.hpp"

namespace {

namespace so3 = varia::so3;

using varia::sdk::groups::RowMajor;

// The minimal API of SE(3) (varia/sdk/lie_group.hpp).
struct RigidMotions {
  static constexpr int point_size = 12, dim = 6;
  // (R1, x1) (R2, x2) = (R1 R2, x1 + R1 x2).
  template <class T>
  static void compose(const T* a, const T* b, T* ab) {
    const Eigen::Map<const RowMajor<T>> Ra(a), Rb(b);
    Eigen::Map<RowMajor<T>>{ab} = Ra * Rb;
    Eigen::Map<so3::Vector3<T>>{ab + 9} = Eigen::Map<const so3::Vector3<T>>(a + 9) + Ra * Eigen::Map<const so3::Vector3<T>>(b + 9);
  }
  // (R, x)^{-1} = (R^{-1}, -R^{-1} x); R^{-1} rather than R^T keeps local the exact inverse of
  // retract for a point that carries round-off (as on SO(3)).
  static void inverse(const double* a, double* a_inverse) {
    const Eigen::Matrix3d Ri = Eigen::Map<const RowMajor<double>>(a).inverse();
    Eigen::Map<RowMajor<double>>{a_inverse} = Ri;
    Eigen::Map<Eigen::Vector3d>{a_inverse + 9} = -Ri * Eigen::Map<const Eigen::Vector3d>(a + 9);
  }
  template <class T>
  static void exp(const T* xi, T* g) {
    const so3::Vector3<T> w(xi[0], xi[1], xi[2]), rho(xi[3], xi[4], xi[5]);
    Eigen::Map<RowMajor<T>>{g} = so3::exp(w);
    Eigen::Map<so3::Vector3<T>>{g + 9} = so3::dexp(w) * rho;
  }
  template <class T>
  static void log(const T* g, T* xi) {
    const so3::Vector3<T> w = so3::log(so3::Matrix3<T>(Eigen::Map<const RowMajor<T>>(g)));
    Eigen::Map<so3::Vector3<T>>{xi} = w;
    Eigen::Map<so3::Vector3<T>>{xi + 3} = so3::dexp_inverse(w) * Eigen::Map<const so3::Vector3<T>>(g + 9);
  }
  template <class T>
  static void bracket(const T* a, const T* b, T* ab) {
    const Eigen::Map<const so3::Vector3<T>> wa(a), va(a + 3), wb(b), vb(b + 3);
    Eigen::Map<so3::Vector3<T>>{ab} = wa.cross(wb);
    Eigen::Map<so3::Vector3<T>>{ab + 3} = wa.cross(vb) - wb.cross(va);
  }
};

class SE3 final : public varia::sdk::LieGroupManifold<RigidMotions> {
 public:
  static constexpr const char* version = "1.0.0";
  static constexpr const char* parameter_schema = varia::sdk::kNoParameters;
  static constexpr const char* properties = R"json({
    "group": "SE(3) (left multiplication)",
    "chart": "natural: g0 exp(xi), exp(w, rho) = (exp(w), dexp_w rho)",
    "point": "rotation matrix, 9 numbers, row-major, then the position x, 3 numbers",
    "tangent": "left-trivialized, 6 numbers: (Omega, R^T x')"
  })json";

  SE3(const nlohmann::json& parameters, const varia::sdk::Context&) {
    varia::sdk::require_no_parameters(parameters, "SE3");
  }

  bool contains(const double* q, char* why, int why_size) noexcept override {
    for (int i = 9; i < 12; ++i)
      if (!std::isfinite(q[i])) return varia::sdk::explain(why, why_size, "entry %d of the position x is not finite", i - 9);
    return varia::sdk::groups::contains_rotation(q, why, why_size);
  }

  // g0 exp(xi) - g0 = (R0 (exp(w) - I), R0 dexp_w rho) in extended precision, as its double
  // part and the rest (varia/sdk/groups/so3.hpp, rotation_increment).
  bool has_increment() const noexcept override { return true; }
  varia::Status increment(const double* q0, const double* xi, double* dq, double* dq_low) noexcept override {
    using varia::sdk::groups::Extended;
    const so3::Matrix3<Extended> R0 = varia::sdk::groups::rotation_increment(q0, xi, dq, dq_low);
    const so3::Vector3<Extended> w(xi[0], xi[1], xi[2]), rho(xi[3], xi[4], xi[5]);
    varia::sdk::groups::split<3, 1>(so3::Vector3<Extended>(R0 * (so3::dexp(w) * rho)), dq + 9, dq_low + 9);
    return nullptr;
  }

  bool has_constraint() const noexcept override { return true; }
  double constraint_error(const double* q) const noexcept override {
    return so3::orthogonality_error(so3::from_row_major(q));
  }
};

}  // namespace

VARIA_PLUGIN(SE3, manifold, SE3)
