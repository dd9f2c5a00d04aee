// The midpoint rule on [0, 1]: int_0^1 f ~= f(1/2). One node, c = 1/2, b = 1 (paper, sec. 2:
// nodes c_i, weights b_i). Exact for degree 1, symmetric (paper, sec. 3: c_i + c_{n-i} = 1).
#include "fixed_rule.hpp"

namespace {

class Midpoint final : public varia::plugins::FixedRule<1> {
 public:
  static constexpr const char* properties = R"({
    "degree": 1,
    "order": 2,
    "symmetric": true,
    "nodes_include_endpoints": false
  })";
  Midpoint(const nlohmann::json& parameters, const varia::sdk::Context&)
      : FixedRule("midpoint", parameters, {0.5}, {1.0}, 1) {}
};

}  // namespace

VARIA_PLUGIN(Midpoint, quadrature, midpoint)
