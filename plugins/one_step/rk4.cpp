// The classical fourth-order Runge-Kutta method: explicit, order 4, not self-adjoint. With
// Simpson's rule it gives the paper's SVIRK4 / sviRK4Sim, with the Euler-Maclaurin formula
// sviRK4EM (sec. 3 "Examples").
#include "varia/sdk/no_parameters.hpp"
#include "varia/sdk/runge_kutta.hpp"

namespace {

class Rk4 final : public varia::sdk::RungeKutta {
 public:
  static constexpr const char* version = "1.0.0";
  static constexpr const char* parameter_schema = varia::sdk::kNoParameters;
  static constexpr const char* properties = R"({
    "order": 4,
    "self_adjoint": false,
    "symplectic": false,
    "equivariance": "affine",
    "implicit": false
  })";

  Rk4(const nlohmann::json& parameters, const varia::sdk::Context&)
      : RungeKutta(varia::sdk::classic_rk4(), 4, false) {
    varia::sdk::require_no_parameters(parameters, "rk4");
  }
};

}  // namespace

VARIA_PLUGIN(Rk4, one_step, rk4)
