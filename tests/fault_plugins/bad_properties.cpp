// A one-step plugin whose metadata declares a property with the wrong type ("symplectic": "yes"):
// the host reads the properties it acts on once, typed, when it loads a plugin, and refuses this
// file with the reason.
#include "varia/sdk/no_parameters.hpp"
#include "varia/sdk/runge_kutta.hpp"

namespace {

class BadProperties final : public varia::sdk::RungeKutta {
 public:
  static constexpr const char* version = "0.0.1";
  static constexpr const char* parameter_schema = varia::sdk::kNoParameters;
  static constexpr const char* properties = R"({"order": 1, "symplectic": "yes"})";

  BadProperties(const nlohmann::json& parameters, const varia::sdk::Context&)
      : RungeKutta({Eigen::MatrixXd::Zero(1, 1), Eigen::VectorXd::Ones(1), Eigen::VectorXd::Zero(1)}, 1, false) {
    varia::sdk::require_no_parameters(parameters, "fault-bad-properties");
  }
};

}  // namespace

VARIA_PLUGIN(BadProperties, one_step, fault_bad_properties)
