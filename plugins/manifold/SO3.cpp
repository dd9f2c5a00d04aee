// SO(3), the rotation group, as a manifold (varia/sdk/groups/so3.hpp; varia/core/so3.hpp has the
// mathematics). A point is a rotation matrix R, 9 numbers, row-major; tangent vectors, velocities
// and momenta are left-trivialized, 3 numbers (Rdot = R hat(Omega)). The natural chart at R0
// (paper, sec. 2, "Natural charts": psi_{R0}^{-1}(xi) = R0 exp(xi), psi_{R0}(R) = log(R0^T R)) is
//   retract: R = R0 exp(hat xi) (Rodrigues),   local: xi = log(R0^T R), |xi| <= pi.
#include "varia/sdk/groups/so3.hpp"
#include "varia/sdk/no_parameters.hpp"
#include "varia/sdk/plugin.hpp"

namespace {

class SO3 final : public varia::sdk::groups::RotationGroup {
 public:
  static constexpr const char* version = "2.0.0";
  static constexpr const char* parameter_schema = varia::sdk::kNoParameters;
  static constexpr const char* properties = R"json({
    "group": "SO(3) (left multiplication)",
    "chart": "natural: R0 exp(xi), exp by Rodrigues' formula",
    "point": "rotation matrix, 9 numbers, row-major",
    "tangent": "left-trivialized, 3 numbers"
  })json";

  SO3(const nlohmann::json& parameters, const varia::sdk::Context&) {
    varia::sdk::require_no_parameters(parameters, "SO3");
  }
};

}  // namespace

VARIA_PLUGIN(SO3, manifold, SO3)
