// Fault plugin: an effect on particle 0 whose Hessian pattern names coordinate 1 << 28 of its
// single coordinate (space_dim 1). The host must refuse it when it builds the composite (exit 3,
// naming the plugin file and the entry), before anything reads through the pattern.
#include "varia/sdk/no_parameters.hpp"
#include "varia/sdk/particle_effect.hpp"

namespace {

class BadEffectPattern final : public varia::sdk::ParticleEffect {
 public:
  static constexpr const char* version = "0.0.1";
  static constexpr const char* parameter_schema = varia::sdk::kNoParameters;
  static constexpr const char* properties = R"({"potential": "|x_0|^2 / 2, with a Hessian pattern out of range"})";

  BadEffectPattern(const nlohmann::json& parameters, const varia::sdk::Context&) {
    varia::sdk::require_no_parameters(parameters, "fault-bad-effect-pattern");
  }

 private:
  void attach() override {
    use_particle(0, "particle");
    block_pattern({0, 1 << 28});  // the fault: the effect has coordinate 0 only
  }
  void potential(const double* x, double* value, double* gradient, double* hessian) const override {
    if (value != nullptr) *value = 0.5 * x[0] * x[0];
    if (gradient != nullptr) gradient[0] = x[0];
    if (hessian != nullptr) hessian[0] = 1.0, hessian[1] = hessian[2] = hessian[3] = 0.0;
  }
};

}  // namespace

VARIA_PLUGIN(BadEffectPattern, effect, fault_bad_effect_pattern)
