// The implicit midpoint rule y1 = y0 + h f((y0 + y1)/2), the collocation method at c = 1/2:
// order 2, self-adjoint and symplectic. The paper's MID, and with the trapezoidal rule its
// SVIMID (sec. 3 "Examples").
#include "varia/sdk/no_parameters.hpp"
#include "varia/sdk/runge_kutta.hpp"

namespace {

class ImplicitMidpoint final : public varia::sdk::RungeKutta {
 public:
  static constexpr const char* version = "1.0.0";
  static constexpr const char* parameter_schema = varia::sdk::kNoParameters;
  static constexpr const char* properties = R"({
    "order": 2,
    "self_adjoint": true,
    "symplectic": true,
    "equivariance": "affine",
    "implicit": true
  })";

  ImplicitMidpoint(const nlohmann::json& parameters, const varia::sdk::Context&)
      : RungeKutta(varia::sdk::collocation_tableau({0.5}), 2, true) {
    varia::sdk::require_no_parameters(parameters, "implicit-midpoint");
  }
};

}  // namespace

VARIA_PLUGIN(ImplicitMidpoint, one_step, implicit_midpoint)
