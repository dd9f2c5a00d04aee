// A planar chain of N particles of mass m joined to their neighbours by Morse bonds, a model of a
// row of atoms (or of a polymer's backbone) that is strongly anharmonic when stretched:
//
//   L(q, v) = m/2 |v|^2 - sum_{i=0}^{N-2} D (1 - exp(-a (|x_{i+1} - x_i| - r0)))^2,
//
// particle i at x_i = (q_{2i}, q_{2i+1}), so N = dim / 2: the manifold's dimension says how many
// (dim 60: 30 particles, 60 degrees of freedom, 120 position and velocity numbers). Written as a
// term-wise Lagrangian (varia/sdk/termwise_lagrangian.hpp): one kinetic term per velocity number
// and one bond term over the four coordinates of two neighbours, so an evaluation costs time linear
// in N and the Hessian is banded (the worked example of docs/writing-plugins.md). The chain is free:
// L is invariant under the rigid motions of the plane (its linear and angular momentum are
// conserved), which it does not declare. No closed-form solution.
#include <stdexcept>

#include "morse.hpp"
#include "support.hpp"
#include "varia/sdk/termwise_lagrangian.hpp"

namespace {

class MorseChain final : public varia::sdk::TermwiseLagrangian {
 public:
  static constexpr const char* version = "1.0.0";
  static constexpr const char* parameter_schema = R"json({
    "$schema": "http://json-schema.org/draft-07/schema#", "type": "object", "additionalProperties": false,
    "properties": {
      "mass": {"type": "number", "exclusiveMinimum": 0, "default": 1, "description": "m, each particle's mass"},
      "depth": {"type": "number", "exclusiveMinimum": 0, "default": 1,
                "description": "D, the bond's dissociation energy: V(r) = D (1 - exp(-a (r - r0)))^2"},
      "range": {"type": "number", "exclusiveMinimum": 0, "default": 1,
                "description": "a, the bond's inverse width (small oscillations: stiffness 2 D a^2)"},
      "rest_length": {"type": "number", "exclusiveMinimum": 0, "default": 1,
                      "description": "r0, the bond's length at rest"}
    }
  })json";
  static constexpr const char* properties = R"json({
    "lagrangian": "m/2 |v|^2 - sum_i D (1 - exp(-a (|x_{i+1} - x_i| - r0)))^2, x_i = (q_{2i}, q_{2i+1})",
    "energy": "m/2 |v|^2 + sum_i D (1 - exp(-a (|x_{i+1} - x_i| - r0)))^2",
    "manifold": "Rn, even dim >= 4 (dim/2 particles in the plane)",
    "symmetry": "none",
    "momentum_map": null,
    "exact_solution": false
  })json";

  MorseChain(const nlohmann::json& parameters, const varia::sdk::Context& context)
      : TermwiseLagrangian(dimension(context), dimension(context)) {
    const varia::plugins::MorseBond bond{varia::plugins::positive_parameter(parameters, "depth", 1.0),
                                         varia::plugins::positive_parameter(parameters, "range", 1.0),
                                         varia::plugins::positive_parameter(parameters, "rest_length", 1.0)};
    const double m = varia::plugins::positive_parameter(parameters, "mass", 1.0);
    for (int i = 0; i < velocity_size(); ++i)
      add_term([m]<class T>(const varia::sdk::TermVec<T, 1>& x) -> T { return 0.5 * m * x(0) * x(0); }, {velocity(i)});
    for (int i = 0; i + 3 < position_size(); i += 2)
      add_term([bond]<class T>(const varia::sdk::TermVec<T, 4>& x) -> T { return -bond(x(0), x(1), x(2), x(3)); },
               {position(i), position(i + 1), position(i + 2), position(i + 3)});
  }

 private:
  static int dimension(const varia::sdk::Context& context) {
    varia::plugins::require_rn(context, "morse-chain", 4, varia::plugins::kAnyDim);
    if (context.dim % 2 != 0)
      throw std::invalid_argument("morse-chain needs manifold Rn with an even dim (2 numbers a particle), got dim " +
                                  std::to_string(context.dim));
    return context.dim;
  }
};

}  // namespace

VARIA_PLUGIN(MorseChain, lagrangian, morse_chain)
