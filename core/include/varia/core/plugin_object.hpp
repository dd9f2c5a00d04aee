// The plugin boundary (ABI version kAbiVersion). Every object a plugin makes derives from
// PluginObject; its virtual methods take plain buffers, are noexcept, and report failure by
// returning a Status: nullptr on success, otherwise a message owned by the object and valid until
// its next call. No exception crosses the boundary: the SDK adapters (sdk/) convert them, and the
// host-side check() converts the Status back into a PluginFault.
#pragma once

#include <stdexcept>
#include <string>

namespace varia {

// Bumped whenever a virtual interface below or in the kind headers changes layout.
// 2: Lagrangian::gradient_jet, OneStepMethod; 3: Manifold::constraint_error; 4: VectorField's
// Lie group hooks (algebra, move); 5: Manifold::chart_jets, Manifold::local_jets; 6: the chart's
// derivatives as caller-sized arrays (Manifold::chart, Manifold::local_derivatives, replacing the
// jets), Manifold::has_constraint.
inline constexpr int kAbiVersion = 6;

using Status = const char*;

// The plugin kinds. New kinds are appended; existing ones keep their interfaces.
enum class Kind { manifold, quadrature, lagrangian, one_step, effect, force };

class PluginObject {
 public:
  virtual ~PluginObject() = default;
  virtual Kind kind() const noexcept = 0;
};

// A plugin call that failed: thrown on the host side only.
class PluginFault : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Converts a plugin Status into a PluginFault naming the call that failed.
inline void check(Status status, const char* what) {
  if (status != nullptr) throw PluginFault(std::string(what) + ": " + status);
}

}  // namespace varia
