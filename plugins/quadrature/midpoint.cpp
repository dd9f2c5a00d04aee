// The midpoint rule on [0, 1]: int_0^1 f ~= f(1/2). One node, c = 1/2, b = 1 (paper, sec. 2:
// nodes c_i, weights b_i). Exact for degree 1, symmetric (paper, sec. 3: c_i + c_{n-i} = 1).
#include <stdexcept>

#include "varia/core/quadrature.hpp"
#include "varia/sdk/plugin.hpp"

namespace {

class Midpoint final : public varia::Quadrature {
 public:
  static constexpr const char* version = "1.0.0";
  static constexpr const char* parameter_schema = R"({
    "$schema": "http://json-schema.org/draft-07/schema#",
    "type": "object",
    "properties": {},
    "additionalProperties": false
  })";
  static constexpr const char* properties = R"({
    "degree": 1,
    "order": 2,
    "symmetric": true,
    "nodes_include_endpoints": false
  })";

  Midpoint(const nlohmann::json& parameters, const varia::sdk::Context&) {
    if (!parameters.empty())
      throw std::invalid_argument("midpoint takes no parameters, got " + parameters.dump());
  }

  int size() const noexcept override { return 1; }
  const double* nodes() const noexcept override { return &kNode; }
  const double* weights() const noexcept override { return &kWeight; }
  int degree() const noexcept override { return 1; }
  bool symmetric() const noexcept override { return true; }

 private:
  static constexpr double kNode = 0.5, kWeight = 1.0;
};

}  // namespace

VARIA_PLUGIN(Midpoint, quadrature, midpoint)
