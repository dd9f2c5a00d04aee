// The isotropic harmonic oscillator on Rn (the paper's "Simple Harmonic Oscillator", sec. 7,
// there with m = k = 1): L(q, v) = m/2 |v|^2 - k/2 |q|^2, so m q'' = -k q.
#include <cmath>

#include "support.hpp"
#include "varia/sdk/autodiff_lagrangian.hpp"

namespace {

class HarmonicOscillator final : public varia::sdk::AutodiffLagrangian<HarmonicOscillator> {
 public:
  static constexpr const char* version = "1.0.0";
  static constexpr const char* parameter_schema = R"json({
    "$schema": "http://json-schema.org/draft-07/schema#",
    "type": "object",
    "properties": {
      "mass": {"type": "number", "exclusiveMinimum": 0, "default": 1,
               "description": "m in L = m/2 |v|^2 - k/2 |q|^2"},
      "stiffness": {"type": "number", "exclusiveMinimum": 0, "default": 1,
                    "description": "k in L = m/2 |v|^2 - k/2 |q|^2"}
    },
    "additionalProperties": false
  })json";
  static constexpr const char* properties = R"json({
    "lagrangian": "m/2 |v|^2 - k/2 |q|^2",
    "energy": "m/2 |v|^2 + k/2 |q|^2",
    "manifold": "Rn, any dim",
    "symmetry": "none",
    "momentum_map": null,
    "exact_solution": true
  })json";

  HarmonicOscillator(const nlohmann::json& parameters, const varia::sdk::Context& context)
      : AutodiffLagrangian(dimension(context), dimension(context)),
        mass_(varia::plugins::positive_parameter(parameters, "mass", 1.0)),
        stiffness_(varia::plugins::positive_parameter(parameters, "stiffness", 1.0)),
        omega_(std::sqrt(stiffness_ / mass_)) {}

  template <class T>
  T lagrangian(const varia::sdk::Vec<T>& q, const varia::sdk::Vec<T>& v) const {
    return T(0.5 * mass_) * v.dot(v) - T(0.5 * stiffness_) * q.dot(q);
  }

  bool constant_mass_matrix(double* mass) const noexcept override {
    varia::plugins::write_scaled_identity(mass, velocity_size(), mass_);
    return true;
  }

  bool has_exact_solution() const noexcept override { return true; }
  // q(t) = q0 cos(wt) + v0/w sin(wt), v(t) = -w q0 sin(wt) + v0 cos(wt), w = sqrt(k/m), each
  // coordinate on its own.
  varia::Status exact_solution(const double* q0, const double* v0, double t, double* q,
                               double* v) noexcept override {
    return varia::sdk::guarded(error_, [&] {
      const double c = std::cos(omega_ * t), s = std::sin(omega_ * t);
      for (int i = 0; i < velocity_size(); ++i) {
        const double qi = q0[i], vi = v0[i];  // q and v may alias q0 and v0
        q[i] = qi * c + vi / omega_ * s;
        v[i] = -omega_ * qi * s + vi * c;
      }
    });
  }

 private:
  static int dimension(const varia::sdk::Context& context) {
    varia::plugins::require_rn(context, "harmonic-oscillator", 1, varia::plugins::kAnyDim);
    return context.dim;
  }

  double mass_, stiffness_, omega_;
};

}  // namespace

VARIA_PLUGIN(HarmonicOscillator, lagrangian, harmonic_oscillator)
