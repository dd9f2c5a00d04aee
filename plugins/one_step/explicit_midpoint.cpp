// The explicit midpoint rule y1 = y0 + h f(y0 + h/2 f(y0)): explicit, order 2, not self-adjoint.
#include "varia/sdk/no_parameters.hpp"
#include "varia/sdk/runge_kutta.hpp"

namespace {

class ExplicitMidpoint final : public varia::sdk::RungeKutta {
 public:
  static constexpr const char* version = "1.0.0";
  static constexpr const char* parameter_schema = varia::sdk::kNoParameters;
  static constexpr const char* properties = R"({
    "order": 2,
    "self_adjoint": false,
    "symplectic": false,
    "equivariance": "affine",
    "implicit": false
  })";

  ExplicitMidpoint(const nlohmann::json& parameters, const varia::sdk::Context&)
      : RungeKutta(varia::sdk::explicit_midpoint(), 2, false) {
    varia::sdk::require_no_parameters(parameters, "explicit-midpoint");
  }
};

}  // namespace

VARIA_PLUGIN(ExplicitMidpoint, one_step, explicit_midpoint)
