// Constructions as parts (OpenFOAM's runtime selection, in-process): each construction of a
// discrete Hamiltonian map lives in one file of this folder, which holds everything the
// construction means to the host: the keys of the scene's "method" that it takes (its JSON
// schema, read once into typed options), how it is built from the parts, what the paper's
// theorems predict of it under their hypotheses, and how it is described in summaries. The host
// finds constructions in one table (table.cpp); adding a construction is adding a file here and a
// line there (docs/architecture.md, "Adding a construction").
#pragma once

#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "varia/abi/manifold.hpp"
#include "varia/core/verification.hpp"

namespace varia::host {

struct Scene;
struct Assembly;
class Registry;

// A construction's own keys of "method", read by it (each construction derives its own).
struct MethodOptions {
  virtual ~MethodOptions() = default;
};

class Construction {
 public:
  virtual ~Construction() = default;
  // The scene's method.construction.
  virtual const char* name() const = 0;
  // The JSON schema (draft-07) of the whole "method" object when this construction is named
  // (method_schema() in parts.hpp composes it from the construction's own keys).
  virtual nlohmann::json schema() const = 0;
  // Reads the method object (already checked against schema()) into typed options; InputError
  // with the JSON pointer for what a schema cannot say.
  virtual std::shared_ptr<const MethodOptions> read(const nlohmann::json& method) const = 0;
  // Whether it takes the system's forces (the discrete Lagrange-d'Alembert principle).
  virtual bool takes_forces() const { return false; }
  // Whether it takes holonomic constraints (system.constraints) on this manifold structure, by
  // multipliers in its equations (docs/constraints.md).
  virtual bool takes_constraints(ManifoldStructure /*structure*/) const { return false; }
  // Creates the construction's own plugin objects and the map into `assembly`, whose manifold,
  // Lagrangian and forces are made; InputError (with the pointer) for a composition it cannot
  // serve.
  virtual void build(const Scene& scene, Registry& registry, Assembly& assembly) const = 0;
  // What the theorems promise of the assembled integrator (paper, sec. 2 and 3), from what its
  // parts declare.
  virtual Predictions predict(const Scene& scene, const Assembly& assembly) const = 0;
  // One line for summaries: "galerkin degree 2, quadrature gauss-lobatto {"points":3}".
  virtual std::string describe(const Scene& scene) const = 0;
};

// The reference integrator that `cost` and `verify` measure against where the system has no
// closed-form solution: `scene` with its method replaced by a Galerkin construction of the given
// degree with `points` Gauss-Legendre points, of order min(2 degree, 2 points) (paper, sec. 2),
// for the same system, forces and start (galerkin.cpp); with constraints (the assembly `a` of
// `scene` has them), degree + 1 Lobatto points, of order 2 degree (Jay).
Scene galerkin_reference(const Scene& scene, const Assembly& a, int degree, int points);

// The table: the construction named `name`, or an InputError at /method/construction listing the
// available ones.
const Construction& construction_named(const std::string& name);
std::vector<std::string> construction_names();
// The names of those that take forces, for messages: "'galerkin' and 'shooting'".
std::string constructions_taking_forces();

}  // namespace varia::host
