// A rigid body hanging on a spring, on SE(3): principal moments J = diag(inertia) about its centre
// of mass, mass m, position x of the centre of mass and attitude R (g = (R, x), velocity
// (Omega, u = R^T x')); its body point `attachment` a (body frame, offset from the centre of mass)
// hangs from the fixed point `anchor` c on a spring of stiffness k and rest length l, under gravity
// g along -e3:
//   L = 1/2 Omega . J Omega + m/2 |u|^2 - m g x_3 - k/2 (|x + R a - c| - l)^2
// (|x'| = |u|). L is invariant under the rotations about the vertical through c,
// (R, x) -> (Q R, c + Q (x - c)) with (Omega, u) unchanged; the Noether momentum is the vertical
// angular momentum about c, e3 . ((x - c) x m x' + R J Omega), x' = R u.
#include <Eigen/Geometry>

#include "rigid_body.hpp"
#include "support.hpp"

namespace {

using varia::plugins::positive_parameter;
using varia::plugins::vector3_parameter;

class SpringSuspendedBody final : public varia::sdk::AutodiffLagrangian<SpringSuspendedBody, 12, 6> {
 public:
  static constexpr const char* version = "1.0.0";
  static constexpr const char* parameter_schema = R"json({
    "$schema": "http://json-schema.org/draft-07/schema#",
    "type": "object",
    "properties": {
      "inertia": {"type": "array", "items": {"type": "number", "exclusiveMinimum": 0},
                  "minItems": 3, "maxItems": 3, "default": [1, 1, 1],
                  "description": "J1, J2, J3: the principal moments of inertia about the centre of mass"},
      "mass": {"type": "number", "exclusiveMinimum": 0, "default": 1, "description": "m"},
      "attachment": {"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3,
                     "default": [0, 0, 1],
                     "description": "a, the body point the spring holds (body frame, offset from the centre of mass)"},
      "anchor": {"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3,
                 "default": [0, 0, 0], "description": "c, the fixed end of the spring"},
      "stiffness": {"type": "number", "exclusiveMinimum": 0, "default": 1, "description": "k"},
      "rest_length": {"type": "number", "minimum": 0, "default": 1, "description": "l"},
      "gravity": {"type": "number", "minimum": 0, "default": 1,
                  "description": "g, the gravitational acceleration, along -e3"}
    },
    "additionalProperties": false
  })json";
  static constexpr const char* properties = R"json({
    "lagrangian": "1/2 Omega . J Omega + m/2 |x'|^2 - m g x_3 - k/2 (|x + R a - c| - l)^2",
    "energy": "1/2 Omega . J Omega + m/2 |x'|^2 + m g x_3 + k/2 (|x + R a - c| - l)^2",
    "manifold": "SE3",
    "symmetry": "SO(2), rotations about the vertical through the anchor c",
    "momentum_map": "e3 . ((x - c) x m x' + R J Omega)",
    "exact_solution": false
  })json";

  SpringSuspendedBody(const nlohmann::json& parameters, const varia::sdk::Context& context)
      : inertia_(vector3_parameter(parameters, "inertia", true, Eigen::Vector3d::Ones())),
        attachment_(vector3_parameter(parameters, "attachment", false, Eigen::Vector3d::UnitZ())),
        anchor_(vector3_parameter(parameters, "anchor", false, Eigen::Vector3d::Zero())),
        mass_(positive_parameter(parameters, "mass", 1.0)),
        stiffness_(positive_parameter(parameters, "stiffness", 1.0)),
        rest_length_(non_negative(parameters, "rest_length", 1.0)),
        gravity_(non_negative(parameters, "gravity", 1.0)) {
    if (context.manifold != "SE3" || context.point_size != 12 || context.dim != 6)
      throw std::invalid_argument("spring-suspended-body needs manifold SE3, got " + context.manifold +
                                  " with dim " + std::to_string(context.dim));
  }

  // q = (R row-major, x), v = (Omega, u).
  template <class T>
  T lagrangian(const varia::sdk::Vec<T>& q, const varia::sdk::Vec<T>& v) const {
    T kinetic = T(0.0), stretch2 = T(0.0);
    for (int i = 0; i < 3; ++i) {
      kinetic += T(0.5 * inertia_(i)) * v(i) * v(i) + T(0.5 * mass_) * v(3 + i) * v(3 + i);
      T arm = q(9 + i) - T(anchor_(i));
      for (int j = 0; j < 3; ++j) arm += q(3 * i + j) * T(attachment_(j));
      stretch2 += arm * arm;
    }
    using std::sqrt;
    const T stretch = sqrt(stretch2) - T(rest_length_);
    return kinetic - T(mass_ * gravity_) * q(11) - T(0.5 * stiffness_) * stretch * stretch;
  }

  bool constant_mass_matrix(double* mass) const noexcept override {
    Eigen::Map<Eigen::Matrix<double, 6, 6>> M(mass);
    M.setZero();
    M.diagonal() << inertia_, Eigen::Vector3d::Constant(mass_);
    return true;
  }

  const char* symmetry_group() const noexcept override { return "SO(2)"; }
  int momentum_size() const noexcept override { return 1; }
  varia::Status momentum(const double* q, const double* v, double* J) noexcept override {
    return varia::sdk::guarded(error_, [&] {
      const Eigen::Matrix3d R = varia::so3::from_row_major(q);
      const Eigen::Vector3d x(q[9], q[10], q[11]), omega(v[0], v[1], v[2]), u(v[3], v[4], v[5]);
      const Eigen::Vector3d spatial = (x - anchor_).cross(mass_ * (R * u)) + R * inertia_.cwiseProduct(omega);
      J[0] = spatial(2);
    });
  }
  // (Q R, c + Q (x - c)) for Q a rotation about e3; the body velocities are unchanged.
  varia::Status act(unsigned seed, const double* q, const double* v, double* gq, double* gv) noexcept override {
    return varia::sdk::guarded(error_, [&] {
      const Eigen::Vector3d vertical = Eigen::Vector3d::UnitZ();
      const Eigen::Matrix3d Q = varia::plugins::random_rotation(seed, &vertical);
      varia::so3::to_row_major(Q * varia::so3::from_row_major(q), gq);
      Eigen::Map<Eigen::Vector3d>{gq + 9} = anchor_ + Q * (Eigen::Vector3d(q[9], q[10], q[11]) - anchor_);
      for (int i = 0; i < 6; ++i) gv[i] = v[i];
    });
  }

 private:
  static double non_negative(const nlohmann::json& parameters, const char* key, double fallback) {
    if (!parameters.contains(key)) return fallback;
    const auto& value = parameters.at(key);
    if (!value.is_number() || !(value.get<double>() >= 0) || !std::isfinite(value.get<double>()))
      throw std::invalid_argument(std::string("parameter '") + key + "' must be a number >= 0, got " + value.dump());
    return value.get<double>();
  }

  Eigen::Vector3d inertia_, attachment_, anchor_;
  double mass_, stiffness_, rest_length_, gravity_;
};

}  // namespace

VARIA_PLUGIN(SpringSuspendedBody, lagrangian, spring_suspended_body)
