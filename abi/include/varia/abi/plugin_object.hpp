// The plugin boundary (ABI version kAbiVersion). Every object a plugin makes derives from
// PluginObject; its virtual methods take plain buffers, are noexcept, and report failure by
// returning a Status: nullptr on success, otherwise a message owned by the object and valid until
// its next call. No exception crosses the boundary: the SDK adapters (sdk/) convert them, and the
// host-side check() converts the Status back into a PluginFault.
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>

namespace varia {

// Bumped whenever a virtual interface below or in the kind headers changes layout.
// 2: Lagrangian::gradient_jet, OneStepMethod; 3: Manifold::constraint_error; 4: VectorField's
// Lie group hooks (algebra, move); 5: Manifold::chart_jets, Manifold::local_jets; 6: the chart's
// derivatives as caller-sized arrays (Manifold::chart, Manifold::local_derivatives, replacing the
// jets), Manifold::has_constraint, Lagrangian::evaluates_at_jets, PluginObject::origin;
// 7: Manifold::translate, Manifold::generators; 9: Manifold::has_increment, Manifold::increment;
// 10: Lagrangian::hessian_jet, Lagrangian::hessian_jet_variables.
// 11: Effect::gradient_jet, Effect::evaluates_at_jets; 12: Lagrangian::has_constant_mass_matrix;
// 13: Lagrangian::runs_verlet_steps, Lagrangian::verlet_steps, Lagrangian::gradients.
// 14: Lagrangian::runs_shots, Lagrangian::shoot, OneStepMethod::explicit_tableau.
// 15: Lagrangian::offers and Lagrangian::run, one entry point for every kernel (kernels.hpp),
// replacing runs_verlet_steps, verlet_steps, runs_shots and shoot; Manifold::structure(),
// replacing is_vector_space(). A kernel added or changed later
// is a new id or version of kernels.hpp, not a new ABI version. Exported functions a plugin may
// add without changing the layout of any interface (varia_create_parts, for parts) are not new
// versions either: a plugin that lacks one keeps loading, and is refused only where it is needed.
// 16: the constraint kind (constraint.hpp, Kind::constraint); Lagrangian::space_dim.
// 17: Manifold::defining_constraint (an embedded manifold served with its equations' multipliers).
// 18: Constraint::quadratic (a constant Hessian, which the shooting construction's shot needs).
// 19: Lagrangian::hessian_jet gives rows of the Hessian times directions the caller sizes.
// 20: Constraint::curvature_derivative (the derivative in q of v^T H_i(q) v, for implicit methods).
inline constexpr int kAbiVersion = 20;

using Status = const char*;

// How a plugin's factory marks the refusal of a parameter value (a std::invalid_argument in the
// SDK), so that the host reports it as bad input at the parameter's JSON pointer (exit 2) rather
// than as a plugin fault (exit 3).
inline constexpr const char* kRefusedParameter = "refused parameter: ";
// The refusal's own message when a factory's error carries the mark, else null.
inline const char* refused_parameter(const char* error) {
  const std::string_view text(error), mark(kRefusedParameter);
  return text.substr(0, mark.size()) == mark ? error + mark.size() : nullptr;
}

// The plugin kinds. New kinds are appended; existing ones keep their interfaces.
enum class Kind { manifold, quadrature, lagrangian, one_step, effect, force, constraint };

class PluginObject;

// A part of a composed object (a product's factors, a composite's terms): an object the host made
// from one of the plugin's parameters, which the plugin's parameter schema marks as parts of a
// kind ("x-varia-part": "<kind>" on the property, whose value is one plugin object or an array of
// them). The host passes them by role (the property's name), in the order they appear, to the
// plugin's factory varia_create_parts; it owns them and keeps them alive as long as the object
// made from them. A plugin that takes no parts need not export that factory.
struct Part {
  const char* role;
  PluginObject* object;
};

class PluginObject {
 public:
  virtual ~PluginObject() = default;
  virtual Kind kind() const noexcept = 0;
  // Who made the object, set by the host when it creates it (its plugin record; opaque to the
  // plugin and to the core) and carried by every fault the core raises about the object, so that
  // a fault names its plugin from the object that failed, not from the words of its message.
  const void* origin() const noexcept { return origin_; }
  void set_origin(const void* origin) noexcept { origin_ = origin; }

 private:
  const void* origin_ = nullptr;
};

// A plugin call that failed: thrown on the host side only, with the failing object's origin.
class PluginFault : public std::runtime_error {
 public:
  explicit PluginFault(const std::string& what, const void* origin = nullptr)
      : std::runtime_error(what), origin_(origin) {}
  const void* origin() const { return origin_; }

 private:
  const void* origin_;
};

// Converts the Status of a call of `source` into a PluginFault naming the call that failed.
inline void check(const PluginObject& source, Status status, const char* what) {
  if (status != nullptr) throw PluginFault(std::string(what) + ": " + status, source.origin());
}

}  // namespace varia
