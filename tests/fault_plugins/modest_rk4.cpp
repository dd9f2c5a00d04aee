// A one-step plugin that understates its order, for `varia verify`'s tests: the classical rk4
// method declaring order 2. verify must report the measured order 4, more than 1 above the
// prediction, as not holding: no theorem explains it.
#include "varia/sdk/no_parameters.hpp"
#include "varia/sdk/runge_kutta.hpp"

namespace {

class ModestRk4 final : public varia::sdk::RungeKutta {
 public:
  static constexpr const char* version = "0.0.1";
  static constexpr const char* parameter_schema = varia::sdk::kNoParameters;
  static constexpr const char* properties =
      R"({"order": 2, "self_adjoint": false, "symplectic": false, "equivariance": "affine", "implicit": false})";

  ModestRk4(const nlohmann::json& parameters, const varia::sdk::Context&)
      : RungeKutta(varia::sdk::classic_rk4(), /*order: understated*/ 2, false) {
    varia::sdk::require_no_parameters(parameters, "modest-rk4");
  }
};

}  // namespace

VARIA_PLUGIN(ModestRk4, one_step, modest_rk4)
