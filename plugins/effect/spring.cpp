// A linear spring between two particles (`between`: [i, j]) or from a particle to a fixed point
// (`anchor`, `particle`): V = k/2 (|d| - r)^2 with d = x_i - x_j (or x_i - anchor), rest length r.
// With u = d/|d|: dV/dx_i = k (|d| - r) u, and d2V/dx_i^2 = k ((1 - r/|d|) I + (r/|d|) u u^T)
// (the Hessian of |d| is (I - u u^T)/|d|); for `between`, x_j enters with the opposite sign.
#include <cmath>

#include "../lagrangian/support.hpp"
#include "varia/sdk/particle_effect.hpp"

namespace {

class Spring final : public varia::sdk::ParticleEffect {
 public:
  static constexpr const char* version = "1.0.0";
  static constexpr const char* parameter_schema = R"json({
    "$schema": "http://json-schema.org/draft-07/schema#",
    "type": "object",
    "properties": {
      "stiffness": {"type": "number", "exclusiveMinimum": 0, "default": 1, "description": "k"},
      "rest_length": {"type": "number", "minimum": 0, "default": 0, "description": "r"},
      "between": {"type": "array", "items": {"type": "integer", "minimum": 0}, "minItems": 2, "maxItems": 2,
                  "description": "the two particles the spring joins"},
      "anchor": {"type": "array", "items": {"type": "number"}, "minItems": 1,
                 "description": "a fixed point (space_dim numbers) the spring ties `particle` to"},
      "particle": {"type": "integer", "minimum": 0, "description": "the particle tied to `anchor`"}
    },
    "oneOf": [
      {"required": ["between"], "not": {"anyOf": [{"required": ["anchor"]}, {"required": ["particle"]}]}},
      {"required": ["anchor", "particle"], "not": {"required": ["between"]}}
    ],
    "examples": [{"between": [0, 2], "stiffness": 3, "rest_length": 0.7}, {"between": [3, 1]},
                 {"anchor": [0.1], "particle": 1, "stiffness": 2, "rest_length": 0.2},
                 {"anchor": [0.1, 0.2, 0.3], "particle": 1, "stiffness": 2, "rest_length": 0.2}],
    "additionalProperties": false
  })json";
  static constexpr const char* properties = R"json({
    "potential": "k/2 (|x_i - x_j| - r)^2, or k/2 (|x_i - anchor| - r)^2",
    "coordinates": "the particles named"
  })json";

  Spring(const nlohmann::json& parameters, const varia::sdk::Context&)
      : k_(varia::plugins::positive_parameter(parameters, "stiffness", 1.0)),
        r_(parameters.value("rest_length", 0.0)),
        anchor_(varia::sdk::vector_parameter(parameters, "anchor")) {
    if (!(r_ >= 0)) throw std::invalid_argument("parameter 'rest_length' must be >= 0");
    if (parameters.contains("between")) {
      const auto& between = parameters.at("between");
      if (!between.is_array() || between.size() != 2)
        throw std::invalid_argument("parameter 'between' must be two particle indices");
      ends_ = {varia::sdk::particle_index(between[0], "between"), varia::sdk::particle_index(between[1], "between")};
      if (ends_[0] == ends_[1]) throw std::invalid_argument("parameter 'between' must name two different particles");
    } else if (parameters.contains("anchor") && parameters.contains("particle")) {
      ends_ = {varia::sdk::particle_index(parameters.at("particle"), "particle")};
    } else {
      throw std::invalid_argument("a spring needs 'between', or 'anchor' and 'particle'");
    }
  }

 private:
  void attach() override {
    if (ends_.size() == 1) check_space_vector(anchor_, "anchor");
    for (int i : ends_) use_particle(i, ends_.size() == 1 ? "particle" : "between");
    dense_pattern();
  }

  void potential(const double* x, double* value, double* gradient, double* hessian) const override {
    const Eigen::Map<const Eigen::VectorXd> xi(x, d_);
    const Eigen::VectorXd d =
        xi - (ends_.size() == 2 ? Eigen::Map<const Eigen::VectorXd>(x + d_, d_) : Eigen::Map<const Eigen::VectorXd>(anchor_.data(), d_));
    const double length = d.norm();
    if (r_ > 0 && length == 0.0)
      throw std::domain_error("a spring of positive rest length has both ends at one point");
    const double ratio = r_ > 0 ? r_ / length : 0.0;  // r/|d|
    if (value != nullptr) *value = 0.5 * k_ * (length - r_) * (length - r_);
    const double sign[2] = {1.0, -1.0};
    const int ends = static_cast<int>(ends_.size());
    if (gradient != nullptr)
      for (int a = 0; a < ends; ++a)
        Eigen::Map<Eigen::VectorXd>(gradient + a * d_, d_) = sign[a] * k_ * (1.0 - ratio) * d;
    if (hessian == nullptr) return;
    const Eigen::MatrixXd block = k_ * ((1.0 - ratio) * Eigen::MatrixXd::Identity(d_, d_) +
                                        (ratio / (length * length)) * d * d.transpose());
    Eigen::Map<Eigen::MatrixXd> H(hessian, ends * d_, ends * d_);  // dense_pattern: column-major
    for (int a = 0; a < ends; ++a)
      for (int b = 0; b < ends; ++b) H.block(a * d_, b * d_, d_, d_) = sign[a] * sign[b] * block;
  }

  double k_, r_;
  std::vector<double> anchor_;
  std::vector<int> ends_;
};

}  // namespace

VARIA_PLUGIN(Spring, effect, spring)
