// An effect plugin whose gradient is wrong, for the effect conformance suite's tests: particle 0
// tied to the origin by a unit spring, V = |x_0|^2 / 2, whose exact gradient x_0 it reports
// multiplied by 1.5 (its Hessian, the identity, is right). It runs, and a composite of it drifts in
// energy; varia-conformance must refuse it, naming the gradient.
#include "varia/sdk/no_parameters.hpp"
#include "varia/sdk/particle_effect.hpp"

namespace {

class WrongGradient final : public varia::sdk::ParticleEffect {
 public:
  static constexpr const char* version = "0.0.1";
  static constexpr const char* parameter_schema = varia::sdk::kNoParameters;
  static constexpr const char* properties = R"({"potential": "|x_0|^2 / 2, with its gradient reported 1.5 x_0"})";

  WrongGradient(const nlohmann::json& parameters, const varia::sdk::Context&) {
    varia::sdk::require_no_parameters(parameters, "wrong-gradient");
  }

 private:
  void attach() override {
    use_particle(0, "particle");
    dense_pattern();
  }
  void potential(const double* x, double* value, double* gradient, double* hessian) const override {
    if (value != nullptr) *value = 0.0;
    for (int k = 0; k < d_; ++k) {
      if (value != nullptr) *value += 0.5 * x[k] * x[k];
      if (gradient != nullptr) gradient[k] = 1.5 * x[k];  // the fault: the gradient is x
      if (hessian != nullptr)
        for (int j = 0; j < d_; ++j) hessian[j * d_ + k] = j == k ? 1.0 : 0.0;
    }
  }
};

}  // namespace

VARIA_PLUGIN(WrongGradient, effect, wrong_gradient)
