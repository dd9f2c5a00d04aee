// Simpson's rule on [0, 1]: int_0^1 f ~= (f(0) + 4 f(1/2) + f(1))/6. Exact for degree 3 (one more
// than its three nodes suggest, by symmetry) and symmetric; the quadrature of the paper's
// sviRK4Sim method (sec. 3, "Examples": RK4 shooting with Simpson's rule).
#include "fixed_rule.hpp"

namespace {

class Simpson final : public varia::plugins::FixedRule<3> {
 public:
  static constexpr const char* properties = R"({
    "degree": 3,
    "order": 4,
    "symmetric": true,
    "nodes_include_endpoints": true
  })";
  Simpson(const nlohmann::json& parameters, const varia::sdk::Context&)
      : FixedRule("simpson", parameters, {0.0, 0.5, 1.0}, {1.0 / 6, 2.0 / 3, 1.0 / 6}, 3) {}
};

}  // namespace

VARIA_PLUGIN(Simpson, quadrature, simpson)
