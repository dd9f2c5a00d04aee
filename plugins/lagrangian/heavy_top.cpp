// The heavy top: a rigid body with one point fixed, in uniform gravity along -e3,
//   L(R, Omega) = 1/2 Omega . J Omega - m g e3 . (R chi),
// J = diag(inertia), chi = center_of_mass, the body-frame offset of the centre of mass from the
// fixed point. The potential torque on the body is m g Gamma x chi, Gamma = R^T e3 (it is the
// left-trivialized dL/dR). L is invariant under rotations about the vertical, R -> exp(a e3) R;
// the Noether momentum is the vertical component e3 . (R J Omega) of the spatial angular momentum.
#include "rigid_body.hpp"
#include "support.hpp"

namespace {

class HeavyTop final : public varia::plugins::RigidBodyLagrangian<HeavyTop> {
 public:
  static constexpr const char* version = "1.0.0";
  static constexpr const char* parameter_schema = R"json({
    "$schema": "http://json-schema.org/draft-07/schema#",
    "type": "object",
    "properties": {
      "inertia": {"type": "array", "items": {"type": "number", "exclusiveMinimum": 0},
                  "minItems": 3, "maxItems": 3, "default": [1, 1, 1],
                  "description": "J1, J2, J3: the principal moments of inertia about the fixed point"},
      "mass": {"type": "number", "exclusiveMinimum": 0, "default": 1, "description": "m"},
      "gravity": {"type": "number", "exclusiveMinimum": 0, "default": 1,
                  "description": "g, the gravitational acceleration, along -e3"},
      "center_of_mass": {"type": "array", "items": {"type": "number"},
                         "minItems": 3, "maxItems": 3, "default": [0, 0, 1],
                         "description": "chi, the body-frame offset of the centre of mass from the fixed point"}
    },
    "additionalProperties": false
  })json";
  static constexpr const char* properties = R"json({
    "lagrangian": "1/2 Omega . J Omega - m g e3 . (R chi)",
    "energy": "1/2 Omega . J Omega + m g e3 . (R chi)",
    "manifold": "SO3",
    "symmetry": "SO(2), rotations about the vertical e3",
    "momentum_map": "e3 . (R J Omega)",
    "exact_solution": false
  })json";

  HeavyTop(const nlohmann::json& parameters, const varia::sdk::Context& context)
      : RigidBodyLagrangian(parameters, context, "heavy-top"),
        weight_(varia::plugins::positive_parameter(parameters, "mass", 1.0) *
                varia::plugins::positive_parameter(parameters, "gravity", 1.0)),
        center_(varia::plugins::vector3_parameter(parameters, "center_of_mass", false,
                                                  Eigen::Vector3d::UnitZ())) {}

  // The height of the centre of mass is e3 . (R chi), the third row of R (row-major q) dotted
  // with chi.
  template <class T>
  T lagrangian(const varia::sdk::Vec<T>& q, const varia::sdk::Vec<T>& v) const {
    T height = T(0.0);
    for (int j = 0; j < 3; ++j) height += q(6 + j) * T(center_(j));
    return kinetic(v) - T(weight_) * height;
  }

  const char* symmetry_group() const noexcept override { return "SO(2)"; }
  int momentum_size() const noexcept override { return 1; }
  varia::Status momentum(const double* q, const double* v, double* J) noexcept override {
    return varia::sdk::guarded(error_, [&] { J[0] = spatial_momentum(q, v)(2); });
  }

 private:
  const Eigen::Vector3d* symmetry_axis() const noexcept override { return &vertical_; }

  double weight_;  // m g
  Eigen::Vector3d center_;
  const Eigen::Vector3d vertical_ = Eigen::Vector3d::UnitZ();
};

}  // namespace

VARIA_PLUGIN(HeavyTop, lagrangian, heavy_top)
