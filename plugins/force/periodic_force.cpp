// A periodic drive f(t) = A cos(w t) (spec: "Composed systems: effects": `amplitude` A, a vector
// of the manifold's dimension, and `frequency` w, in radians per unit time). It depends on
// neither q nor v: no Jacobian entries.
#include <cmath>
#include <stdexcept>

#include "varia/sdk/force_base.hpp"

namespace {

class PeriodicForce final : public varia::sdk::ForceBase {
 public:
  static constexpr const char* version = "1.0.0";
  static constexpr const char* parameter_schema = R"json({
    "$schema": "http://json-schema.org/draft-07/schema#",
    "type": "object",
    "properties": {
      "amplitude": {"type": "array", "items": {"type": "number"}, "minItems": 1,
                    "description": "A in f = A cos(w t), one number per dimension"},
      "frequency": {"type": "number", "default": 1, "description": "w in f = A cos(w t) (angular)"}
    },
    "required": ["amplitude"],
    "examples": [{"amplitude": [0.5], "frequency": 1.3}, {"amplitude": [0.5, -0.2], "frequency": 2},
                 {"amplitude": [0.5, -0.2, 0.1]}, {"amplitude": [1, 2, 3, 4], "frequency": 0.7}],
    "additionalProperties": false
  })json";
  static constexpr const char* properties = R"json({
    "force": "A cos(w t)",
    "time_dependent": true
  })json";

  PeriodicForce(const nlohmann::json& parameters, const varia::sdk::Context& context)
      : ForceBase(context),
        amplitude_(parameters.at("amplitude").get<std::vector<double>>()),
        frequency_(parameters.value("frequency", 1.0)) {
    if (static_cast<int>(amplitude_.size()) != n_)
      throw std::invalid_argument("parameter 'amplitude' must have " + std::to_string(n_) +
                                  " numbers (the manifold's dimension), got " + std::to_string(amplitude_.size()));
  }

 private:
  void apply(double t, const double*, const double*, double* force, double*) const override {
    const double c = std::cos(frequency_ * t);
    for (int i = 0; i < n_; ++i) force[i] = amplitude_[i] * c;
  }

  std::vector<double> amplitude_;
  double frequency_;
};

}  // namespace

VARIA_PLUGIN(PeriodicForce, force, periodic_force)
