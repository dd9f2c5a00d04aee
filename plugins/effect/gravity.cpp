// Uniform gravity on every particle: V = -sum_i m_i <g, x_i>, so m_i x_i'' = m_i g. Its Hessian
// is zero: no entries.
#include "varia/sdk/particle_effect.hpp"

namespace {

class Gravity final : public varia::sdk::TemplatedEffect<Gravity> {
 public:
  static constexpr const char* version = "1.0.0";
  static constexpr const char* parameter_schema = R"json({
    "$schema": "http://json-schema.org/draft-07/schema#",
    "type": "object",
    "properties": {
      "g": {"type": "array", "items": {"type": "number"}, "minItems": 1,
            "description": "the acceleration of gravity, a space_dim-vector"}
    },
    "required": ["g"],
    "examples": [{"g": [-1.0]}, {"g": [0.0, -9.81]}, {"g": [0.0, 0.5, -9.81]}],
    "additionalProperties": false
  })json";
  static constexpr const char* properties = R"json({
    "potential": "-sum_i m_i <g, x_i>",
    "coordinates": "all"
  })json";

  Gravity(const nlohmann::json& parameters, const varia::sdk::Context&)
      : g_(varia::sdk::vector_parameter(parameters, "g")) {}

 private:
  void attach() override {
    check_space_vector(g_, "g");
    for (int i = 0; i < particles_; ++i) use_particle(i, "g");
  }

  friend varia::sdk::TemplatedEffect<Gravity>;
  void second_order(const double*, double*) const {}  // no pattern entries
  // V and dV/dx at doubles or jets.
  template <class T>
  void first_order(const T* x, T* value, T* gradient) const {
    if (value != nullptr) *value = T(0.0);
    for (int i = 0; i < particles_; ++i)
      for (int k = 0; k < d_; ++k) {
        const int j = i * d_ + k;
        if (value != nullptr) *value -= masses_[i] * g_[k] * x[j];
        if (gradient != nullptr) gradient[j] = T(-masses_[i] * g_[k]);
      }
  }

  std::vector<double> g_;
};

}  // namespace

VARIA_PLUGIN(Gravity, effect, gravity)
