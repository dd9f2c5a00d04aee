// The planar double pendulum: a bob of mass m1 on a massless rod of length l1 from a fixed pivot,
// and a bob of mass m2 on a rod of length l2 from the first bob, in gravity g. With the angles
// q = (theta1, theta2) of the rods from the downward vertical (Goldstein, "Classical Mechanics",
// 3rd ed., sec. 1.6 and 6.4):
//
//   L(q, v) = (m1 + m2)/2 l1^2 v1^2 + m2/2 l2^2 v2^2 + m2 l1 l2 v1 v2 cos(theta1 - theta2)
//             + (m1 + m2) g l1 cos theta1 + m2 g l2 cos theta2.
//
// Its mass matrix [[(m1 + m2) l1^2, m2 l1 l2 cos(theta1 - theta2)], [., m2 l2^2]] depends on the
// configuration (positive definite: det = l1^2 l2^2 m2 (m1 + m2 sin^2(theta1 - theta2)) > 0), so
// the Galerkin construction solves its IDEL by Newton's method at every degree, and the motion is
// chaotic at high energy. No symmetry, no closed-form solution.
#include <cmath>

#include "support.hpp"
#include "varia/sdk/autodiff_lagrangian.hpp"

namespace {

class DoublePendulum final : public varia::sdk::AutodiffLagrangian<DoublePendulum, 2, 2> {
 public:
  static constexpr const char* version = "1.0.0";
  static constexpr const char* parameter_schema = R"json({
    "$schema": "http://json-schema.org/draft-07/schema#", "type": "object", "additionalProperties": false,
    "properties": {
      "mass1": {"type": "number", "exclusiveMinimum": 0, "default": 1,
                "description": "m1, the first (upper) bob's mass"},
      "mass2": {"type": "number", "exclusiveMinimum": 0, "default": 1,
                "description": "m2, the second (lower) bob's mass"},
      "length1": {"type": "number", "exclusiveMinimum": 0, "default": 1,
                  "description": "l1, the rod from the pivot to the first bob"},
      "length2": {"type": "number", "exclusiveMinimum": 0, "default": 1,
                  "description": "l2, the rod from the first bob to the second"},
      "gravity": {"type": "number", "exclusiveMinimum": 0, "default": 1,
                  "description": "g, the gravitational acceleration (q = 0 hangs down)"}
    }
  })json";
  static constexpr const char* properties = R"json({
    "lagrangian": "(m1 + m2)/2 l1^2 v1^2 + m2/2 l2^2 v2^2 + m2 l1 l2 v1 v2 cos(q1 - q2) + (m1 + m2) g l1 cos q1 + m2 g l2 cos q2",
    "energy": "(m1 + m2)/2 l1^2 v1^2 + m2/2 l2^2 v2^2 + m2 l1 l2 v1 v2 cos(q1 - q2) - (m1 + m2) g l1 cos q1 - m2 g l2 cos q2",
    "manifold": "Rn, dim 2",
    "symmetry": "none",
    "momentum_map": null,
    "exact_solution": false
  })json";

  DoublePendulum(const nlohmann::json& parameters, const varia::sdk::Context& context)
      : m1_(varia::plugins::positive_parameter(parameters, "mass1", 1.0)),
        m2_(varia::plugins::positive_parameter(parameters, "mass2", 1.0)),
        l1_(varia::plugins::positive_parameter(parameters, "length1", 1.0)),
        l2_(varia::plugins::positive_parameter(parameters, "length2", 1.0)),
        g_(varia::plugins::positive_parameter(parameters, "gravity", 1.0)) {
    varia::plugins::require_rn(context, "double-pendulum", 2, 2);
  }

  template <class T>
  T lagrangian(const varia::sdk::Vec<T>& q, const varia::sdk::Vec<T>& v) const {
    using std::cos;
    const double outer = m1_ + m2_;
    const T kinetic = (0.5 * outer * l1_ * l1_) * v(0) * v(0) + (0.5 * m2_ * l2_ * l2_) * v(1) * v(1) +
                      (m2_ * l1_ * l2_) * v(0) * v(1) * cos(q(0) - q(1));
    return kinetic + (outer * g_ * l1_) * cos(q(0)) + (m2_ * g_ * l2_) * cos(q(1));
  }

 private:
  double m1_, m2_, l1_, l2_, g_;
};

}  // namespace

VARIA_PLUGIN(DoublePendulum, lagrangian, double_pendulum)
