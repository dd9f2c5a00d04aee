// The free rigid body (the paper's sec. 2 "Example: Lie group velocity Verlet"):
//   L(R, Omega) = 1/2 Omega . J Omega,  J = diag(inertia),
// on SO(3) with the body angular velocity Omega. L is invariant under left multiplication by all
// of SO(3); its Noether momentum is the spatial angular momentum pi = R J Omega.
#include "rigid_body.hpp"

namespace {

class RigidBody final : public varia::plugins::RigidBodyLagrangian<RigidBody> {
 public:
  static constexpr const char* version = "1.0.0";
  static constexpr const char* parameter_schema = R"json({
    "$schema": "http://json-schema.org/draft-07/schema#",
    "type": "object",
    "properties": {
      "inertia": {"type": "array", "items": {"type": "number", "exclusiveMinimum": 0},
                  "minItems": 3, "maxItems": 3, "default": [1, 1, 1],
                  "description": "J1, J2, J3: the principal moments of inertia"}
    },
    "additionalProperties": false
  })json";
  static constexpr const char* properties = R"json({
    "lagrangian": "1/2 Omega . J Omega",
    "energy": "1/2 Omega . J Omega",
    "manifold": "SO3",
    "symmetry": "SO(3), left multiplication",
    "momentum_map": "spatial angular momentum R J Omega",
    "exact_solution": false
  })json";

  RigidBody(const nlohmann::json& parameters, const varia::sdk::Context& context)
      : RigidBodyLagrangian(parameters, context, "rigid-body") {}

  template <class T>
  T lagrangian(const varia::sdk::Vec<T>& /*q*/, const varia::sdk::Vec<T>& v) const {
    return kinetic(v);
  }

  const char* symmetry_group() const noexcept override { return "SO(3)"; }
  int momentum_size() const noexcept override { return 3; }
  varia::Status momentum(const double* q, const double* v, double* J) noexcept override {
    return varia::sdk::guarded(error_, [&] {
      const Eigen::Vector3d pi = spatial_momentum(q, v);
      for (int i = 0; i < 3; ++i) J[i] = pi(i);
    });
  }

 private:
  const Eigen::Vector3d* symmetry_axis() const noexcept override { return nullptr; }
};

}  // namespace

VARIA_PLUGIN(RigidBody, lagrangian, rigid_body)
