// The stiff Fermi–Pasta–Ulam chain (Hairer, Lubich & Wanner, "Geometric Numerical Integration",
// 2nd ed. 2006, sec. I.5.1): 2m unit masses on a line with fixed ends, joined alternately by soft
// nonlinear springs (potential d^4) and m stiff linear springs (stiffness omega^2 on the
// coordinates x1 = (q_{2i} - q_{2i-1})/sqrt 2, i.e. omega^2/4 d^2 in the elongation d):
//
//   L(q, v) = |v|^2/2 - V(q),
//   V(q) = omega^2/4 sum_{i=1..m} (q_{2i} - q_{2i-1})^2 + sum_{i=0..m} (q_{2i+1} - q_{2i})^4,
//
// with q_0 = q_{2m+1} = 0 (the walls); the coordinates here are q_1 ... q_{2m}, stored 0-based.
// The oscillatory energies of the stiff springs, I_j = (y_{1,j}^2 + omega^2 x_{1,j}^2)/2 with
// x_{1,j} = (q_{2j} - q_{2j-1})/sqrt 2 and y_{1,j} its velocity, exchange energy on the time scale
// omega^0 while their sum I = sum_j I_j is conserved up to O(1/omega) over times exponentially long
// in omega (HLW sec. XIII.6); HLW's initial value is m = 3, omega = 50, x_{0,1} = 1, y_{0,1} = 1,
// x_{1,1} = 1/omega, y_{1,1} = 1, the rest 0 (scenes/hard/fpu.json).
//
// No symmetry (the walls break the translations) and no exact solution.
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "support.hpp"
#include "varia/sdk/autodiff_lagrangian.hpp"

namespace {

class Fpu final : public varia::sdk::AutodiffLagrangian<Fpu> {
 public:
  static constexpr const char* version = "1.0.0";
  static constexpr const char* parameter_schema = R"json({
    "$schema": "http://json-schema.org/draft-07/schema#",
    "type": "object",
    "properties": {
      "pairs": {"type": "integer", "minimum": 1, "default": 3,
                "description": "m, the number of stiff springs; the chain has 2m moving masses (manifold Rn with dim 2m)"},
      "omega": {"type": "number", "exclusiveMinimum": 0, "default": 50,
                "description": "the stiff springs' frequency: potential omega^2/4 (q_{2i} - q_{2i-1})^2"}
    },
    "additionalProperties": false
  })json";
  static constexpr const char* properties = R"json({
    "lagrangian": "|v|^2/2 - omega^2/4 sum_i (q_{2i} - q_{2i-1})^2 - sum_i (q_{2i+1} - q_{2i})^4, q_0 = q_{2m+1} = 0",
    "energy": "|v|^2/2 + omega^2/4 sum_i (q_{2i} - q_{2i-1})^2 + sum_i (q_{2i+1} - q_{2i})^4",
    "manifold": "Rn, dim 2 pairs",
    "symmetry": "none",
    "momentum_map": null,
    "exact_solution": false
  })json";

  Fpu(const nlohmann::json& parameters, const varia::sdk::Context& context)
      : AutodiffLagrangian(dimension(parameters, context), dimension(parameters, context)),
        pairs_(pairs_of(parameters)),
        omega_(varia::plugins::positive_parameter(parameters, "omega", 50.0)) {}

  template <class T>
  T lagrangian(const varia::sdk::Vec<T>& q, const varia::sdk::Vec<T>& v) const {
    T stiff = T(0.0), soft = T(0.0);
    // Stiff springs: between q_{2i-1} and q_{2i} (1-based), i.e. 0-based (2i-2, 2i-1).
    for (int i = 0; i < pairs_; ++i) {
      const T d = q(2 * i + 1) - q(2 * i);
      stiff += d * d;
    }
    // Soft springs: wall-q_1, q_{2i}-q_{2i+1}, q_{2m}-wall.
    for (int i = 0; i <= pairs_; ++i) {
      const T d = (i < pairs_ ? q(2 * i) : T(0.0)) - (i > 0 ? q(2 * i - 1) : T(0.0));
      const T d2 = d * d;
      soft += d2 * d2;
    }
    return T(0.5) * v.dot(v) - T(0.25 * omega_ * omega_) * stiff - soft;
  }

  bool constant_mass_matrix(double* mass) const noexcept override {
    varia::plugins::write_scaled_identity(mass, velocity_size(), 1.0);
    return true;
  }

 private:
  static int pairs_of(const nlohmann::json& parameters) {
    if (!parameters.contains("pairs")) return 3;
    const auto& value = parameters.at("pairs");
    if (!value.is_number_integer() || value.get<long long>() < 1 ||
        value.get<long long>() > std::numeric_limits<int>::max() / 2)
      throw std::invalid_argument("parameter 'pairs' must be an integer >= 1 (and 2 pairs an int), got " +
                                  value.dump());
    return value.get<int>();
  }
  static int dimension(const nlohmann::json& parameters, const varia::sdk::Context& context) {
    const int n = 2 * pairs_of(parameters);
    varia::plugins::require_rn(context, "fpu", n, n);
    return n;
  }

  int pairs_;
  double omega_;
};

}  // namespace

VARIA_PLUGIN(Fpu, lagrangian, fpu)
