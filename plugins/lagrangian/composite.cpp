// The composite particle system (spec: "Composed systems: effects"; core/composite.hpp). This
// plugin carries the type's metadata and parameter schema. The host builds a scene's composite in
// core from `space_dim`, `masses` and the effect objects it creates from `terms` (docs/effects.md);
// made directly, as here, the plugin is the system without terms: free particles.
#include <stdexcept>

#include "support.hpp"
#include "varia/core/composite.hpp"

namespace {

class Composite final : public varia::CompositeLagrangian {
 public:
  static constexpr const char* version = "1.0.0";
  static constexpr const char* parameter_schema = R"json({
    "$schema": "http://json-schema.org/draft-07/schema#",
    "type": "object",
    "properties": {
      "space_dim": {"type": "integer", "minimum": 1, "maximum": 3, "default": 1,
                    "description": "d: the dimension of the space the particles move in"},
      "masses": {"type": "array", "items": {"type": "number", "exclusiveMinimum": 0}, "minItems": 1,
                 "default": [1], "description": "one mass per particle; n = d x (number of masses)"},
      "terms": {"type": "array", "description": "potential effects, each an effect plugin object",
                "items": {"type": "object", "required": ["type"],
                          "properties": {"type": {"type": "string", "minLength": 1}}}}
    },
    "additionalProperties": false
  })json";
  static constexpr const char* properties = R"json({
    "lagrangian": "1/2 sum_i m_i |v_i|^2 - sum_terms V",
    "manifold": "Rn, dim = space_dim x number of masses",
    "symmetry": "none",
    "hessian": "sparse"
  })json";

  Composite(const nlohmann::json& parameters, const varia::sdk::Context& context)
      : CompositeLagrangian(parameters.value("space_dim", 1), masses(parameters), {}) {
    varia::plugins::require_rn(context, "composite", velocity_size(), velocity_size());
    if (!parameters.value("terms", nlohmann::json::array()).empty())
      throw std::invalid_argument(
          "composite: the terms are effect plugins that the host creates; made directly, a composite has no terms");
  }

 private:
  static std::vector<double> masses(const nlohmann::json& parameters) {
    return parameters.value("masses", std::vector<double>{1.0});
  }
};

}  // namespace

VARIA_PLUGIN(Composite, lagrangian, composite)
