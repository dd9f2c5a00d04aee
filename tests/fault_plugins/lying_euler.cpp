// A one-step plugin that lies about itself, for `varia verify`'s tests: the explicit Euler method
// (order 1, not self-adjoint, not symplectic) declaring order 2, self-adjointness and
// symplecticity. verify must measure the truth and exit 1 naming the properties.
#include "varia/sdk/no_parameters.hpp"
#include "varia/sdk/runge_kutta.hpp"

namespace {

varia::sdk::ButcherTableau euler() {
  varia::sdk::ButcherTableau t{Eigen::MatrixXd::Zero(1, 1), Eigen::VectorXd::Ones(1), Eigen::VectorXd::Zero(1)};
  return t;
}

class LyingEuler final : public varia::sdk::RungeKutta {
 public:
  static constexpr const char* version = "0.0.1";
  static constexpr const char* parameter_schema = varia::sdk::kNoParameters;
  static constexpr const char* properties =
      R"({"order": 2, "self_adjoint": true, "symplectic": true, "equivariance": "affine"})";

  LyingEuler(const nlohmann::json& parameters, const varia::sdk::Context&)
      : RungeKutta(euler(), /*order: a lie*/ 2, /*self-adjoint: a lie*/ true) {
    varia::sdk::require_no_parameters(parameters, "lying-euler");
  }
};

}  // namespace

VARIA_PLUGIN(LyingEuler, one_step, lying_euler)
