// N rigid bodies hanging from a fixed pivot at the origin, each joined to the next by a ball joint,
// in gravity g along -e3 (spec: "Constrained systems, S2 and products"), on the product of N SO3:
// the position is the attitudes R_1..R_N (9 numbers each, row-major), the velocity the body angular
// velocities Omega_1..Omega_N (R_i' = R_i hat(Omega_i)). Body i's upper joint is at o_i (o_1 = 0,
// the pivot), its centre of mass at c_i = o_i + R_i com_i and the next joint at o_{i+1} =
// o_i + R_i next_i, so that
//   c_i' = o_i' + R_i (Omega_i x com_i),   o_{i+1}' = o_i' + R_i (Omega_i x next_i),
//   L = sum_i 1/2 m_i |c_i'|^2 + 1/2 Omega_i . J_i Omega_i - m_i g e3 . c_i,
// with J_i = diag(inertia_i), the principal moments about the centre of mass. The joints are the
// coordinates themselves: no constraint is left to enforce. L is invariant under rotations about
// the vertical, R_i -> Q R_i for all i (Omega unchanged); its Noether momentum is the angular
// momentum about the pivot along e3, e3 . sum_i (m_i c_i x c_i' + R_i J_i Omega_i).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "rigid_body.hpp"
#include "support.hpp"

namespace {

using varia::sdk::Vec;

struct Body {
  double mass = 1.0;
  Eigen::Vector3d inertia, com, next;
};

// One default body when "bodies" is not given.
nlohmann::json bodies_of(const nlohmann::json& parameters) {
  return parameters.value("bodies", nlohmann::json::array({nlohmann::json::object()}));
}

std::vector<Body> bodies_parameter(const nlohmann::json& parameters) {
  std::vector<Body> bodies;
  const auto list = bodies_of(parameters);
  for (std::size_t i = 0; i < list.size(); ++i) {
    const auto& b = list[i];
    Body body;
    body.mass = varia::plugins::positive_parameter(b, "mass", 1.0);
    body.inertia = varia::plugins::vector3_parameter(b, "inertia", true, Eigen::Vector3d::Ones());
    body.com = varia::plugins::vector3_parameter(b, "com", false, Eigen::Vector3d(0, 0, -0.5));
    body.next = varia::plugins::vector3_parameter(b, "next", false, Eigen::Vector3d(0, 0, -1));
    bodies.push_back(body);
  }
  return bodies;
}

std::string product_of_so3(std::size_t n) {
  std::string name = "product(";
  for (std::size_t i = 0; i < n; ++i) name += i > 0 ? ",SO3" : "SO3";
  return name + ")";
}

int dimension(const nlohmann::json& parameters, const varia::sdk::Context& context) {
  const std::size_t n = bodies_of(parameters).size();
  if (context.manifold != product_of_so3(n))
    throw std::invalid_argument("rigid-body-chain: " + std::to_string(n) + " bodies need the manifold " +
                                product_of_so3(n) + " (a product with one SO3 factor per body), got " +
                                context.manifold);
  return static_cast<int>(3 * n);
}

// a x b with b constant.
template <class T>
Eigen::Matrix<T, 3, 1> cross(const Eigen::Matrix<T, 3, 1>& a, const Eigen::Vector3d& b) {
  return {a(1) * b(2) - a(2) * b(1), a(2) * b(0) - a(0) * b(2), a(0) * b(1) - a(1) * b(0)};
}

// R b, R the row-major 3 x 3 matrix at q(first), b constant.
template <class T>
Eigen::Matrix<T, 3, 1> rotate(const Vec<T>& q, int first, const Eigen::Matrix<T, 3, 1>& b) {
  Eigen::Matrix<T, 3, 1> r;
  for (int i = 0; i < 3; ++i) r(i) = q(first + 3 * i) * b(0) + q(first + 3 * i + 1) * b(1) + q(first + 3 * i + 2) * b(2);
  return r;
}

class RigidBodyChain final : public varia::sdk::AutodiffLagrangian<RigidBodyChain> {
 public:
  static constexpr const char* version = "1.0.0";
  static constexpr const char* parameter_schema = R"json({
    "$schema": "http://json-schema.org/draft-07/schema#",
    "type": "object",
    "properties": {
      "bodies": {
        "type": "array", "minItems": 1,
        "default": [{"mass": 1, "inertia": [1, 1, 1], "com": [0, 0, -0.5], "next": [0, 0, -1]}],
        "description": "the bodies from the pivot down, each {mass, inertia, com, next}",
        "items": {
          "type": "object",
          "properties": {
            "mass": {"type": "number", "exclusiveMinimum": 0, "default": 1, "description": "m_i"},
            "inertia": {"type": "array", "items": {"type": "number", "exclusiveMinimum": 0},
                        "minItems": 3, "maxItems": 3, "default": [1, 1, 1],
                        "description": "the principal moments of inertia about the centre of mass"},
            "com": {"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3,
                    "default": [0, 0, -0.5],
                    "description": "body frame: from the body's upper joint to its centre of mass"},
            "next": {"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3,
                     "default": [0, 0, -1],
                     "description": "body frame: from the body's upper joint to the next body's joint"}
          },
          "additionalProperties": false
        }
      },
      "gravity": {"type": "number", "minimum": 0, "default": 1,
                  "description": "g, the gravitational acceleration, along -e3"}
    },
    "additionalProperties": false
  })json";
  static constexpr const char* properties = R"json({
    "lagrangian": "sum_i 1/2 m_i |c_i'|^2 + 1/2 Omega_i . J_i Omega_i - m_i g e3 . c_i, c_i = o_i + R_i com_i, o_{i+1} = o_i + R_i next_i, o_1 = 0",
    "energy": "sum_i 1/2 m_i |c_i'|^2 + 1/2 Omega_i . J_i Omega_i + m_i g e3 . c_i",
    "manifold": "product of N SO3, one per body",
    "symmetry": "SO(2), rotations about the vertical e3 (R_i -> Q R_i)",
    "momentum_map": "e3 . sum_i (m_i c_i x c_i' + R_i J_i Omega_i)",
    "exact_solution": false
  })json";

  RigidBodyChain(const nlohmann::json& parameters, const varia::sdk::Context& context)
      : AutodiffLagrangian(3 * dimension(parameters, context), dimension(parameters, context)),
        bodies_(bodies_parameter(parameters)),
        gravity_(parameters.value("gravity", 1.0)) {}

  template <class T>
  T lagrangian(const Vec<T>& q, const Vec<T>& v) const {
    using V3 = Eigen::Matrix<T, 3, 1>;
    V3 joint = V3::Constant(T(0.0)), joint_velocity = V3::Constant(T(0.0));
    T L = T(0.0);
    for (std::size_t i = 0; i < bodies_.size(); ++i) {
      const Body& b = bodies_[i];
      const int first = static_cast<int>(9 * i);
      const V3 omega(v(3 * i), v(3 * i + 1), v(3 * i + 2));
      const V3 centre_velocity = joint_velocity + rotate(q, first, cross(omega, b.com));
      const T height = joint(2) + q(first + 6) * b.com(0) + q(first + 7) * b.com(1) + q(first + 8) * b.com(2);
      L -= b.mass * gravity_ * height;
      for (int k = 0; k < 3; ++k)
        L += 0.5 * b.mass * centre_velocity(k) * centre_velocity(k) + 0.5 * b.inertia(k) * omega(k) * omega(k);
      joint += rotate(q, first, V3(T(b.next(0)), T(b.next(1)), T(b.next(2))));
      joint_velocity += rotate(q, first, cross(omega, b.next));
    }
    return L;
  }

  const char* symmetry_group() const noexcept override { return "SO(2)"; }
  int momentum_size() const noexcept override { return 1; }
  varia::Status momentum(const double* q, const double* v, double* J) noexcept override {
    return varia::sdk::guarded(error_, [&] { J[0] = vertical_momentum(q, v); });
  }
  // Q R_i for one rotation Q about e3; the body velocities are unchanged.
  varia::Status act(unsigned seed, const double* q, const double* v, double* gq, double* gv) noexcept override {
    return varia::sdk::guarded(error_, [&] {
      const Eigen::Vector3d vertical = Eigen::Vector3d::UnitZ();
      const Eigen::Matrix3d Q = varia::plugins::random_rotation(seed, &vertical);
      for (std::size_t i = 0; i < bodies_.size(); ++i) {
        varia::so3::to_row_major(Q * varia::so3::from_row_major(q + 9 * i), gq + 9 * i);
        for (int k = 0; k < 3; ++k) gv[3 * i + k] = v[3 * i + k];
      }
    });
  }

 private:
  double vertical_momentum(const double* q, const double* v) const {
    Eigen::Vector3d joint = Eigen::Vector3d::Zero(), joint_velocity = Eigen::Vector3d::Zero();
    double sum = 0.0;
    for (std::size_t i = 0; i < bodies_.size(); ++i) {
      const Body& b = bodies_[i];
      const Eigen::Matrix3d R = varia::so3::from_row_major(q + 9 * i);
      const Eigen::Vector3d omega(v[3 * i], v[3 * i + 1], v[3 * i + 2]);
      const Eigen::Vector3d centre = joint + R * b.com, centre_velocity = joint_velocity + R * omega.cross(b.com);
      sum += (b.mass * centre.cross(centre_velocity) + R * b.inertia.cwiseProduct(omega))(2);
      joint += R * b.next;
      joint_velocity += R * omega.cross(b.next);
    }
    return sum;
  }

  std::vector<Body> bodies_;
  double gravity_;
};

}  // namespace

VARIA_PLUGIN(RigidBodyChain, lagrangian, rigid_body_chain)
