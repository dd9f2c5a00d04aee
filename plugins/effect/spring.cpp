// Linear springs of one stiffness k and rest length r: V = k/2 (|d| - r)^2 for each, with
// d = x_i - x_j for a spring between two particles, or d = x_i - anchor for a particle tied to a
// fixed point. One term holds one spring (`between`: [i, j]; `anchor` and `particle`) or many:
// `pairs` lists the particles each joins, `chain`: [first, last] joins each particle of
// first..last to the next, so that a chain of N particles is one term, not N - 1 (the compact form
// for many similar springs, docs/effects.md). With u = d/|d|: dV/dx_i = k (|d| - r) u, and
// d2V/dx_i^2 = k ((1 - r/|d|) I + (r/|d|) u u^T) (the Hessian of |d| is (I - u u^T)/|d|); x_j
// enters with the opposite sign. Each spring contributes the dense block of its two particles to
// the Hessian pattern, so a chain's Hessian is block tridiagonal.
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "../lagrangian/support.hpp"
#include "varia/sdk/particle_effect.hpp"

namespace {

constexpr int kAnchor = -1;  // the far end of a spring tied to `anchor`

class Spring final : public varia::sdk::TemplatedEffect<Spring> {
 public:
  static constexpr const char* version = "1.1.0";
  static constexpr const char* parameter_schema = R"json({
    "$schema": "http://json-schema.org/draft-07/schema#",
    "type": "object",
    "properties": {
      "stiffness": {"type": "number", "exclusiveMinimum": 0, "default": 1, "description": "k"},
      "rest_length": {"type": "number", "minimum": 0, "default": 0, "description": "r"},
      "between": {"type": "array", "items": {"type": "integer", "minimum": 0}, "minItems": 2, "maxItems": 2,
                  "description": "the two particles the spring joins"},
      "pairs": {"type": "array", "minItems": 1,
                "items": {"type": "array", "items": {"type": "integer", "minimum": 0}, "minItems": 2, "maxItems": 2},
                "description": "many springs: the two particles each joins"},
      "chain": {"type": "array", "items": {"type": "integer", "minimum": 0}, "minItems": 2, "maxItems": 2,
                "description": "[first, last]: a spring from each particle of first..last to the next"},
      "anchor": {"type": "array", "items": {"type": "number"}, "minItems": 1,
                 "description": "a fixed point (space_dim numbers) the spring ties `particle` to"},
      "particle": {"type": "integer", "minimum": 0, "description": "the particle tied to `anchor`"}
    },
    "oneOf": [
      {"required": ["between"],
       "not": {"anyOf": [{"required": ["pairs"]}, {"required": ["chain"]}, {"required": ["anchor"]}, {"required": ["particle"]}]}},
      {"required": ["pairs"],
       "not": {"anyOf": [{"required": ["between"]}, {"required": ["chain"]}, {"required": ["anchor"]}, {"required": ["particle"]}]}},
      {"required": ["chain"],
       "not": {"anyOf": [{"required": ["between"]}, {"required": ["pairs"]}, {"required": ["anchor"]}, {"required": ["particle"]}]}},
      {"required": ["anchor", "particle"],
       "not": {"anyOf": [{"required": ["between"]}, {"required": ["pairs"]}, {"required": ["chain"]}]}}
    ],
    "examples": [{"between": [0, 2], "stiffness": 3, "rest_length": 0.7}, {"between": [3, 1]},
                 {"pairs": [[0, 1], [2, 1], [3, 0]], "stiffness": 2, "rest_length": 0.5}, {"chain": [0, 3]},
                 {"anchor": [0.1], "particle": 1, "stiffness": 2, "rest_length": 0.2},
                 {"anchor": [0.1, 0.2, 0.3], "particle": 1, "stiffness": 2, "rest_length": 0.2}],
    "additionalProperties": false
  })json";
  static constexpr const char* properties = R"json({
    "potential": "sum over its springs of k/2 (|x_i - x_j| - r)^2, or k/2 (|x_i - anchor| - r)^2",
    "coordinates": "the particles named"
  })json";

  Spring(const nlohmann::json& parameters, const varia::sdk::Context&)
      : k_(varia::plugins::positive_parameter(parameters, "stiffness", 1.0)),
        r_(parameters.value("rest_length", 0.0)),
        anchor_(varia::sdk::vector_parameter(parameters, "anchor")) {
    if (!(r_ >= 0)) throw std::invalid_argument("parameter 'rest_length' must be >= 0");
    if (parameters.contains("between")) {
      key_ = "between";
      add_pair(parameters.at("between"));
    } else if (parameters.contains("pairs")) {
      key_ = "pairs";
      const auto& pairs = parameters.at("pairs");
      if (!pairs.is_array() || pairs.empty()) throw std::invalid_argument("parameter 'pairs' must be a list of pairs");
      for (const auto& pair : pairs) add_pair(pair);
    } else if (parameters.contains("chain")) {
      key_ = "chain";
      add_chain(parameters.at("chain"));
    } else if (parameters.contains("anchor") && parameters.contains("particle")) {
      key_ = "particle";
      springs_.push_back({varia::sdk::particle_index(parameters.at("particle"), "particle"), kAnchor});
    } else {
      throw std::invalid_argument("a spring needs 'between', 'pairs', 'chain', or 'anchor' and 'particle'");
    }
  }

 private:
  // A spring between the two particles of `pair` (the parameter key_ names it).
  void add_pair(const nlohmann::json& pair) {
    const std::string what = "parameter '" + key_ + "'";
    if (!pair.is_array() || pair.size() != 2) throw std::invalid_argument(what + " must give two particle indices");
    const int i = varia::sdk::particle_index(pair[0], key_.c_str()), j = varia::sdk::particle_index(pair[1], key_.c_str());
    if (i == j) throw std::invalid_argument(what + " must name two different particles");
    springs_.push_back({i, j});
  }
  void add_chain(const nlohmann::json& ends) {
    if (!ends.is_array() || ends.size() != 2) throw std::invalid_argument("parameter 'chain' must be [first, last]");
    const int first = varia::sdk::particle_index(ends[0], "chain"), last = varia::sdk::particle_index(ends[1], "chain");
    if (first >= last) throw std::invalid_argument("parameter 'chain' must be [first, last] with first < last, got " + ends.dump());
    for (int i = first; i < last; ++i) springs_.push_back({i, i + 1});
  }

  // Each particle's coordinates once (local slots in the order first named), each spring's block.
  void attach() override {
    if (springs_[0][1] == kAnchor) check_space_vector(anchor_, "anchor");
    std::map<int, int> slot;
    for (auto& spring : springs_)
      for (int& end : spring) {
        if (end == kAnchor) continue;
        const auto [it, added] = slot.try_emplace(end, static_cast<int>(slot.size()));
        if (added) use_particle(end, key_.c_str());
        end = it->second;
      }
    for (const auto& spring : springs_) {
      std::vector<int> block;
      for (int end : spring)
        for (int a = 0; end != kAnchor && a < d_; ++a) block.push_back(end * d_ + a);
      block_pattern(block);
    }
    coordinates_ = static_cast<int>(slot.size()) * d_;
    d_buffer_.resize(d_);
  }

  friend varia::sdk::TemplatedEffect<Spring>;
  void second_order(const double* x, double* hessian) const {
    for (const auto& spring : springs_) {
      const int ends = spring[1] == kAnchor ? 1 : 2;
      add_spring_hessian(spring, x, hessian);
      hessian += (ends * d_) * (ends * d_);
    }
  }

  // V and dV/dx at doubles or jets: each spring adds k/2 (|d| - r)^2 and +-k (1 - r/|d|) d at its
  // ends (k/2 |d|^2 and +-k d for r = 0, with no square root: smooth at |d| = 0).
  template <class T>
  void first_order(const T* x, T* value, T* gradient) const {
    using std::sqrt;
    if (value != nullptr) *value = T(0.0);
    if (gradient != nullptr) std::fill(gradient, gradient + coordinates_, T(0.0));
    const double sign[2] = {1.0, -1.0};
    for (const auto& spring : springs_) {
      const int ends = spring[1] == kAnchor ? 1 : 2;
      const auto difference = [&](int a) -> T {
        return ends == 2 ? x[spring[0] * d_ + a] - x[spring[1] * d_ + a] : x[spring[0] * d_ + a] - anchor_[a];
      };
      T length2(0.0);
      for (int a = 0; a < d_; ++a) length2 += difference(a) * difference(a);
      T factor(k_);  // k (1 - r/|d|)
      if (r_ > 0) {
        if (varia::value_of(length2) == 0.0)
          throw std::domain_error("a spring of positive rest length has both ends at one point");
        const T length = sqrt(length2);
        if (value != nullptr) *value += 0.5 * k_ * (length - r_) * (length - r_);
        factor = k_ * (1.0 - r_ / length);
      } else if (value != nullptr) {
        *value += 0.5 * k_ * length2;
      }
      if (gradient == nullptr) continue;
      for (int e = 0; e < ends; ++e)
        for (int a = 0; a < d_; ++a) gradient[spring[e] * d_ + a] += sign[e] * factor * difference(a);
    }
  }

  // One spring's Hessian block (its 2d x 2d or d x d values, column-major).
  void add_spring_hessian(const std::array<int, 2>& spring, const double* x, double* hessian) const {
    const int ends = spring[1] == kAnchor ? 1 : 2;
    const double* far = ends == 2 ? x + spring[1] * d_ : anchor_.data();
    double* d = d_buffer_.data();
    double length2 = 0.0;
    for (int a = 0; a < d_; ++a) {
      d[a] = x[spring[0] * d_ + a] - far[a];
      length2 += d[a] * d[a];
    }
    const double ratio = r_ > 0 ? r_ / std::sqrt(length2) : 0.0;  // r/|d|
    const double sign[2] = {1.0, -1.0};
    const int size = ends * d_;  // block_pattern's order: column-major over (end, a)
    for (int e = 0; e < ends; ++e)
      for (int b = 0; b < d_; ++b)
        for (int f = 0; f < ends; ++f)
          for (int a = 0; a < d_; ++a) {
            const double block = k_ * ((1.0 - ratio) * (a == b ? 1.0 : 0.0) + ratio / length2 * d[a] * d[b]);
            hessian[(e * d_ + b) * size + f * d_ + a] = sign[e] * sign[f] * block;
          }
  }

  double k_, r_;
  std::vector<double> anchor_;
  std::string key_;                         // the parameter that named the particles
  std::vector<std::array<int, 2>> springs_;  // particles (local slots once bound), or kAnchor
  int coordinates_ = 0;                      // the number of coordinates named, once bound
  mutable std::vector<double> d_buffer_;     // x_i - x_j, sized at bind
};

}  // namespace

VARIA_PLUGIN(Spring, effect, spring)
