// The trapezoidal rule on [0, 1]: int_0^1 f ~= (f(0) + f(1))/2. Nodes 0 and 1, weights 1/2 each;
// exact for degree 1 and symmetric. With the midpoint one-step method it gives the paper's
// shooting-based example of sec. 3 ("Examples"), whose nodes include the endpoints.
#include "fixed_rule.hpp"

namespace {

class Trapezoid final : public varia::plugins::FixedRule<2> {
 public:
  static constexpr const char* properties = R"({
    "degree": 1,
    "order": 2,
    "symmetric": true,
    "nodes_include_endpoints": true
  })";
  Trapezoid(const nlohmann::json& parameters, const varia::sdk::Context&)
      : FixedRule("trapezoid", parameters, {0.0, 1.0}, {0.5, 0.5}, 1) {}
};

}  // namespace

VARIA_PLUGIN(Trapezoid, quadrature, trapezoid)
