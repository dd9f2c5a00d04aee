// A central (Kepler) attraction of one particle of mass m to a fixed center c:
// V = -mu m / |d|, d = x - c; dV/dx = mu m d / |d|^3, d2V/dx2 = mu m (I / |d|^3 - 3 d d^T / |d|^5).
#include <cmath>

#include "../lagrangian/support.hpp"
#include "varia/sdk/particle_effect.hpp"

namespace {

class Central final : public varia::sdk::TemplatedEffect<Central> {
 public:
  static constexpr const char* version = "1.0.0";
  static constexpr const char* parameter_schema = R"json({
    "$schema": "http://json-schema.org/draft-07/schema#",
    "type": "object",
    "properties": {
      "mu": {"type": "number", "exclusiveMinimum": 0, "default": 1, "description": "mu in V = -mu m / |x - c|"},
      "particle": {"type": "integer", "minimum": 0, "description": "the attracted particle"},
      "center": {"type": "array", "items": {"type": "number"}, "minItems": 1,
                 "description": "the fixed center c, space_dim numbers (default: the origin)"}
    },
    "required": ["particle"],
    "examples": [{"particle": 2}, {"particle": 1, "mu": 2, "center": [0.5, -1.0, 0.2]}],
    "additionalProperties": false
  })json";
  static constexpr const char* properties = R"json({
    "potential": "-mu m_i / |x_i - center|",
    "coordinates": "the particle named"
  })json";

  Central(const nlohmann::json& parameters, const varia::sdk::Context&)
      : mu_(varia::plugins::positive_parameter(parameters, "mu", 1.0)),
        particle_(varia::sdk::particle_index(parameters.at("particle"), "particle")),
        center_(varia::sdk::vector_parameter(parameters, "center")) {}

 private:
  void attach() override {
    if (center_.empty()) center_.assign(d_, 0.0);
    check_space_vector(center_, "center");
    use_particle(particle_, "particle");
    dense_pattern();
  }

  friend varia::sdk::TemplatedEffect<Central>;
  void second_order(const double* x, double* hessian) const {
    const Eigen::VectorXd d =
        Eigen::Map<const Eigen::VectorXd>(x, d_) - Eigen::Map<const Eigen::VectorXd>(center_.data(), d_);
    const double r = d.norm();
    Eigen::Map<Eigen::MatrixXd>(hessian, d_, d_) =
        mu_ * masses_[particle_] / (r * r * r) * (Eigen::MatrixXd::Identity(d_, d_) - 3.0 / (r * r) * d * d.transpose());
  }
  // V = -k/r and dV/dx = k d / r^3 (d = x - center, r = |d|) at doubles or jets.
  template <class T>
  void first_order(const T* x, T* value, T* gradient) const {
    using std::sqrt;
    T s(0.0);
    for (int a = 0; a < d_; ++a) s += (x[a] - center_[a]) * (x[a] - center_[a]);
    if (varia::value_of(s) == 0.0) throw std::domain_error("a particle is at the center of a central attraction");
    const double k = mu_ * masses_[particle_];
    const T r = sqrt(s);
    if (value != nullptr) *value = -k / r;
    if (gradient == nullptr) return;
    const T c = k / (r * r * r);
    for (int a = 0; a < d_; ++a) gradient[a] = c * (x[a] - center_[a]);
  }

  double mu_;
  int particle_;
  std::vector<double> center_;
};

}  // namespace

VARIA_PLUGIN(Central, effect, central)
