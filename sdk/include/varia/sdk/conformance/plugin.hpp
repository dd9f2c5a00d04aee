// The conformance suite of one plugin file, whatever its kind: its metadata (the parameter
// schema and properties are JSON objects; the schema's defaults are the constructor's defaults),
// then the suite of its kind over the objects it makes: every quadrature of its integer
// parameters' sweep, every Lagrangian in each context it accepts with default parameters, every
// effect, force and constraint made from each of its schema's "examples" (or from {} without
// examples) in each system it accepts. Kinds without a suite yet have their metadata checked only.
#pragma once

#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "varia/sdk/conformance/constraint.hpp"
#include "varia/sdk/conformance/effect.hpp"
#include "varia/sdk/conformance/failures.hpp"
#include "varia/sdk/conformance/force.hpp"
#include "varia/sdk/conformance/lagrangian.hpp"
#include "varia/sdk/conformance/loader.hpp"
#include "varia/sdk/conformance/quadrature.hpp"

namespace varia::sdk::conformance {

// The contexts a Lagrangian plugin may accept: Rn with dim 1 to 8, SO3, SE3, the products of one
// and two SO3, S2 and the product of two S2 (served in the embedding: velocities of 3 numbers each).
inline std::vector<nlohmann::json> lagrangian_contexts() {
  std::vector<nlohmann::json> contexts;
  for (int n = 1; n <= 8; ++n) contexts.push_back({{"manifold", "Rn"}, {"point_size", n}, {"dim", n}});
  contexts.push_back({{"manifold", "SO3"}, {"point_size", 9}, {"dim", 3}});
  contexts.push_back({{"manifold", "SE3"}, {"point_size", 12}, {"dim", 6}});
  contexts.push_back({{"manifold", "product(SO3)"}, {"point_size", 9}, {"dim", 3}});
  contexts.push_back({{"manifold", "product(SO3,SO3)"}, {"point_size", 18}, {"dim", 6}});
  contexts.push_back({{"manifold", "S2"}, {"point_size", 3}, {"dim", 2}});
  contexts.push_back({{"manifold", "product(S2,S2)"}, {"point_size", 6}, {"dim", 4}});
  return contexts;
}

// The schema's "default" values, as a parameter object.
inline nlohmann::json schema_defaults(const nlohmann::json& schema) {
  nlohmann::json defaults = nlohmann::json::object();
  const nlohmann::json properties = schema.value("properties", nlohmann::json::object());
  for (const auto& [key, property] : properties.items())
    if (property.is_object() && property.contains("default")) defaults[key] = property["default"];
  return defaults;
}

inline void check_metadata(const LoadedPlugin& plugin, Failures& failures) {
  const auto is_object = [](const char* text) {
    return nlohmann::json::accept(text) && nlohmann::json::parse(text).is_object();
  };
  failures.expect(is_object(plugin.info().parameter_schema), "parameter_schema is not a JSON object");
  failures.expect(is_object(plugin.info().properties), "properties is not a JSON object");
}

// Each Lagrangian made with {} in a context it accepts is checked, and agrees with the one made
// from the schema's defaults.
inline void check_lagrangian_plugin(const LoadedPlugin& plugin, Failures& failures) {
  std::mt19937 engine(20240611);
  const nlohmann::json defaults = schema_defaults(plugin.parameter_schema());
  int accepted = 0;
  for (const auto& context : lagrangian_contexts()) {
    std::shared_ptr<Lagrangian> lagrangian;
    try {
      lagrangian = plugin.create<Lagrangian>(nlohmann::json::object(), context);
    } catch (const std::runtime_error&) {
      continue;  // not a context this plugin takes
    }
    ++accepted;
    Failures in_context = check_lagrangian(*lagrangian, engine);
    const auto explicit_ = plugin.create<Lagrangian>(defaults, context);
    const VectorXd q = random_point(lagrangian->position_size(), engine);
    const VectorXd v = random_point(lagrangian->velocity_size(), engine);
    in_context.expect(value(*lagrangian, q, v) == value(*explicit_, q, v),
                      "the schema's defaults are not the defaults of the constructor");
    for (const auto& failure : in_context.list()) failures.expect(false, context.dump(), ": ", failure);
  }
  failures.expect(accepted > 0, "no context accepted with default parameters (Rn of dim 1 to 8, SO3, SE3, products of SO3, S2, S2 x S2)");
}

// The parameter objects an effect or force is made with: the schema's "examples" (draft-07), or
// {} when it has none.
inline std::vector<nlohmann::json> schema_examples(const nlohmann::json& schema) {
  const nlohmann::json examples = schema.value("examples", nlohmann::json::array());
  if (!examples.is_array() || examples.empty()) return {nlohmann::json::object()};
  return examples.get<std::vector<nlohmann::json>>();
}

// The systems an effect is bound to: kEffectParticles particles of distinct masses in 1, 2 and 3
// dimensions. An example that its effect refuses in a system (a vector of another size, a
// particle that does not exist) is skipped there; at least one must be checked.
inline constexpr int kEffectParticles = 4;
inline void check_effect_plugin(const LoadedPlugin& plugin, Failures& failures) {
  std::mt19937 engine(20240611);
  const double masses[kEffectParticles] = {1.0, 1.5, 2.0, 2.5};
  int checked = 0;
  for (const auto& parameters : schema_examples(plugin.parameter_schema()))
    for (int d = 1; d <= 3; ++d) {
      const int n = d * kEffectParticles;
      std::shared_ptr<Effect> effect;
      try {
        effect = plugin.create<Effect>(parameters, {{"manifold", "Rn"}, {"point_size", n}, {"dim", n}});
      } catch (const std::runtime_error&) {
        continue;
      }
      if (effect->bind(d, kEffectParticles, masses) != nullptr) continue;
      ++checked;
      const Failures found = check_effect(*effect, n, engine);
      for (const auto& failure : found.list())
        failures.expect(false, parameters.dump(), " in space_dim ", d, ": ", failure);
    }
  failures.expect(checked > 0, "no example parameters (the schema's \"examples\", else {}) made an effect that binds to ",
                  kEffectParticles, " particles in space_dim 1 to 3");
}

// A constraint bound to each particle system of kEffectParticles particles in 1, 2 and 3
// dimensions that it accepts, for each example; at least one must be checked.
inline void check_constraint_plugin(const LoadedPlugin& plugin, Failures& failures) {
  std::mt19937 engine(20261129);
  int checked = 0;
  for (const auto& parameters : schema_examples(plugin.parameter_schema()))
    for (int d = 1; d <= 3; ++d) {
      const int n = d * kEffectParticles;
      std::shared_ptr<Constraint> constraint;
      try {
        constraint = plugin.create<Constraint>(parameters, {{"manifold", "Rn"}, {"point_size", n}, {"dim", n}});
      } catch (const std::runtime_error&) {
        continue;
      }
      if (constraint->bind(n, d) != nullptr) continue;
      ++checked;
      const Failures found = check_constraint(*constraint, n, engine);
      for (const auto& failure : found.list())
        failures.expect(false, parameters.dump(), " in space_dim ", d, ": ", failure);
    }
  failures.expect(checked > 0, "no example parameters (the schema's \"examples\", else {}) made a constraint that binds to ",
                  kEffectParticles, " particles in space_dim 1 to 3");
}

// A force in each context Rn of dim 1 to 4 that it accepts, for each example.
inline void check_force_plugin(const LoadedPlugin& plugin, Failures& failures) {
  std::mt19937 engine(20240611);
  int checked = 0;
  for (const auto& parameters : schema_examples(plugin.parameter_schema()))
    for (int n = 1; n <= 4; ++n) {
      std::shared_ptr<Force> force;
      try {
        force = plugin.create<Force>(parameters, {{"manifold", "Rn"}, {"point_size", n}, {"dim", n}});
      } catch (const std::runtime_error&) {
        continue;
      }
      ++checked;
      const Failures found = check_force(*force, engine);
      for (const auto& failure : found.list()) failures.expect(false, parameters.dump(), " on Rn of dim ", n, ": ", failure);
    }
  failures.expect(checked > 0, "no example parameters (the schema's \"examples\", else {}) made a force on Rn of dim 1 to 4");
}

inline void check_quadrature_plugin(const LoadedPlugin& plugin, Failures& failures) {
  for (const auto& parameters : parameter_sweep(plugin.parameter_schema())) {
    const Failures found = check_quadrature(*plugin.create<Quadrature>(parameters));  // kept alive for list()
    for (const auto& failure : found.list()) failures.expect(false, parameters.dump(), ": ", failure);
  }
}

// The whole suite for one plugin file; what it checked is appended to `checked`.
inline Failures check_plugin(const LoadedPlugin& plugin, std::string& checked) {
  Failures failures;
  check_metadata(plugin, failures);
  if (!failures.empty()) return failures;
  const std::string kind = plugin.info().kind;
  checked = "metadata";
  try {
    if (kind == "quadrature") {
      check_quadrature_plugin(plugin, failures);
      checked += ", quadrature suite (exactness to the declared degree, nodes, weights, symmetry)";
    } else if (kind == "lagrangian") {
      check_lagrangian_plugin(plugin, failures);
      checked += ", lagrangian suite (derivatives, Hessian symmetry, mass matrix, symmetry, defaults)";
    } else if (kind == "effect") {
      check_effect_plugin(plugin, failures);
      checked += ", effect suite (coordinates, Hessian pattern and symmetry, gradient and Hessian by Taylor tests)";
    } else if (kind == "constraint") {
      check_constraint_plugin(plugin, failures);
      checked += ", constraint suite (Jacobian and Hessian patterns, Jacobian and weighted Hessian by Taylor tests)";
    } else if (kind == "force") {
      check_force_plugin(plugin, failures);
      checked += ", force suite (Jacobian pattern, Jacobian by Taylor tests)";
    }
  } catch (const std::exception& e) {
    failures.expect(false, "failed: ", e.what());
  }
  return failures;
}

}  // namespace varia::sdk::conformance
