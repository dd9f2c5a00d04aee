// A constraint that is not quadratic, for the host's tests: particle 0 of a particle system in
// three dimensions at unit distance from the origin, written as the quartic
//   g(q) = (|x|^4 - 1) / 4,   G = |x|^2 x^T,   Hessian of lambda g = lambda (|x|^2 I + 2 x x^T),
// whose zero set and normal direction are the unit rod's. So every construction that takes it moves
// the spherical pendulum as it does on the `rod` from the anchor at the origin (the multiplier
// differs by the factor |x|^2 = 1), and those that need quadratic constraints refuse it. It gives
// the derivative of c = v^T H v = |x|^2 |v|^2 + 2 (x . v)^2 in x, 2 |v|^2 x + 4 (x . v) v
// (Constraint::curvature_derivative), which implicit one-step methods need, unless its parameter
// "curvature_derivative" is false (a constraint that does not give it, which they refuse). The
// formulas are the core tests' QuarticSphere's (tests/core/sphere_constraints.hpp).
#include <varia/sdk/plugin.hpp>

#include "../core/sphere_constraints.hpp"

namespace {

class QuarticAnchor final : public varia::testing::QuarticSphere {
 public:
  static constexpr const char* version = "0.0.1";
  static constexpr const char* parameter_schema = R"({
    "$schema": "http://json-schema.org/draft-07/schema#",
    "type": "object",
    "properties": {"curvature_derivative": {"type": "boolean", "default": true}},
    "additionalProperties": false
  })";
  static constexpr const char* properties = R"json({"fault": "none (tests only): a constraint that is not quadratic"})json";

  QuarticAnchor(const nlohmann::json& parameters, const varia::sdk::Context&)
      : gives_curvature_derivative_(parameters.value("curvature_derivative", true)) {}
  varia::Status bind(int n, int space_dim) noexcept override {
    return space_dim == 3 && n >= 3 ? nullptr : "quartic-anchor binds to particle 0 of particles in 3 dimensions";
  }
  bool gives_curvature_derivative() const noexcept override { return gives_curvature_derivative_; }

 private:
  bool gives_curvature_derivative_;
};

}  // namespace

VARIA_PLUGIN(QuarticAnchor, constraint, quartic_anchor)
