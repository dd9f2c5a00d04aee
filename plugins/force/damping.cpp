// Linear (Rayleigh) damping f = -c v (spec: "Composed systems: effects"); df/dv = -c I.
#include <stdexcept>

#include "varia/sdk/force_base.hpp"

namespace {

class Damping final : public varia::sdk::ForceBase {
 public:
  static constexpr const char* version = "1.0.0";
  static constexpr const char* parameter_schema = R"json({
    "$schema": "http://json-schema.org/draft-07/schema#",
    "type": "object",
    "properties": {
      "coefficient": {"type": "number", "minimum": 0, "default": 1, "description": "c in f = -c v"}
    },
    "examples": [{"coefficient": 0.3}],
    "additionalProperties": false
  })json";
  static constexpr const char* properties = R"json({
    "force": "-c v",
    "dissipative": true
  })json";

  Damping(const nlohmann::json& parameters, const varia::sdk::Context& context)
      : ForceBase(context), c_(parameters.value("coefficient", 1.0)) {
    if (!(c_ >= 0)) throw std::invalid_argument("parameter 'coefficient' must be a number >= 0");
    if (n_ < 1) throw std::invalid_argument("damping needs a manifold of dimension >= 1");
    for (int i = 0; i < n_; ++i) add_entry(i, m_ + i);
  }

 private:
  void apply(double, const double*, const double* v, double* force, double* jacobian) const override {
    for (int i = 0; i < n_; ++i) {
      force[i] = -c_ * v[i];
      if (jacobian != nullptr) jacobian[i] = -c_;
    }
  }

  double c_;
};

}  // namespace

VARIA_PLUGIN(Damping, force, damping)
