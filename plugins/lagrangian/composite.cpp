// The composite particle system (spec: "Composed systems: effects"; core/composite.hpp): its
// `terms` are its parts, effect objects the host makes from the scene and passes in (the schema's
// "x-varia-part"), so that no plugin loads another. Made without parts, it is free particles.
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
                "x-varia-part": "effect",
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
      : CompositeLagrangian(parameters.value("space_dim", 1), masses(parameters), terms(parameters, context)) {
    varia::plugins::require_rn(context, "composite", velocity_size(), velocity_size());
  }

 private:
  static std::vector<double> masses(const nlohmann::json& parameters) {
    return parameters.value("masses", std::vector<double>{1.0});
  }
  // The effects the host made from "terms", borrowed: the host keeps them alive as long as this.
  static std::vector<std::shared_ptr<varia::Effect>> terms(const nlohmann::json& parameters,
                                                           const varia::sdk::Context& context) {
    std::vector<std::shared_ptr<varia::Effect>> effects;
    for (varia::Effect* effect : context.parts_of<varia::Effect>("terms", varia::Kind::effect))
      effects.emplace_back(effect, [](varia::Effect*) {});
    if (effects.size() != parameters.value("terms", nlohmann::json::array()).size())
      throw std::runtime_error("composite: its terms are effect objects that the host makes; it was given " +
                               std::to_string(effects.size()) + " for " +
                               std::to_string(parameters.value("terms", nlohmann::json::array()).size()) +
                               " terms");
    return effects;
  }
};

}  // namespace

VARIA_PLUGIN(Composite, lagrangian, composite)
