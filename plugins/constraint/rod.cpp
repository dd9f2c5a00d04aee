// Rigid rods of one length L between particles of a particle system (spec: "Constrained systems,
// S2 and products"): |x_i - x_j| = L for a rod between two particles, |x_i - a| = L for a particle
// tied to a fixed anchor a. Each rod is one scalar constraint, written relative to its length so
// that |g| reads as a relative length error:
//   g = (|d|^2 - L^2) / (2 L^2) = (|d| - L) / L + O(((|d| - L) / L)^2),   d = x_i - x_j (or x_i - a),
// with dg/dx_i = d / L^2, dg/dx_j = -d / L^2, and the Hessian of lambda g the constant blocks
// lambda / L^2 [I -I; -I I] (I alone for an anchored particle). A chain of N particles is N - 1
// rows of G with 2 d entries each: its Jacobian and Hessian are sparse (block bidiagonal and
// tridiagonal), so the constructions' cost per step stays linear in N.
#include <algorithm>
#include <array>
#include <string>
#include <vector>

#include "../lagrangian/support.hpp"
#include "varia/abi/constraint.hpp"
#include "varia/abi/sparse_pattern.hpp"
#include "varia/sdk/particle_effect.hpp"

namespace {

constexpr int kAnchor = -1;  // the far end of a rod tied to `anchor`

class Rod final : public varia::Constraint {
 public:
  static constexpr const char* version = "1.0.0";
  static constexpr const char* parameter_schema = R"json({
    "$schema": "http://json-schema.org/draft-07/schema#",
    "type": "object",
    "properties": {
      "length": {"type": "number", "exclusiveMinimum": 0, "default": 1, "description": "L, each rod's length"},
      "between": {"type": "array", "items": {"type": "integer", "minimum": 0}, "minItems": 2, "maxItems": 2,
                  "description": "the two particles the rod joins"},
      "chain": {"type": "array", "items": {"type": "integer", "minimum": 0}, "minItems": 2, "maxItems": 2,
                "description": "[first, last]: a rod from each particle of first..last to the next"},
      "anchor": {"type": "array", "items": {"type": "number"}, "minItems": 1,
                 "description": "a fixed point (space_dim numbers) the rod ties `particle` to"},
      "particle": {"type": "integer", "minimum": 0, "description": "the particle tied to `anchor`"}
    },
    "oneOf": [
      {"required": ["between"], "not": {"anyOf": [{"required": ["chain"]}, {"required": ["anchor"]}, {"required": ["particle"]}]}},
      {"required": ["chain"], "not": {"anyOf": [{"required": ["between"]}, {"required": ["anchor"]}, {"required": ["particle"]}]}},
      {"required": ["anchor", "particle"], "not": {"anyOf": [{"required": ["between"]}, {"required": ["chain"]}]}}
    ],
    "examples": [{"between": [0, 2], "length": 0.7}, {"chain": [0, 3], "length": 1.5},
                 {"anchor": [0.1], "particle": 1, "length": 2}, {"anchor": [0.1, 0.2, 0.3], "particle": 1}],
    "additionalProperties": false
  })json";
  static constexpr const char* properties = R"json({
    "constraint": "(|x_i - x_j|^2 - L^2) / (2 L^2) = 0 for each rod, or (|x_i - anchor|^2 - L^2) / (2 L^2) = 0",
    "system": "a particle system (composite)"
  })json";

  Rod(const nlohmann::json& parameters, const varia::sdk::Context&)
      : length_(varia::plugins::positive_parameter(parameters, "length", 1.0)),
        anchor_(varia::sdk::vector_parameter(parameters, "anchor")) {
    if (parameters.contains("between")) {
      const auto& pair = parameters.at("between");
      const int i = varia::sdk::particle_index(pair.at(0), "between"), j = varia::sdk::particle_index(pair.at(1), "between");
      if (i == j) throw std::invalid_argument("parameter 'between' must name two different particles");
      rods_.push_back({i, j});
    } else if (parameters.contains("chain")) {
      const auto& ends = parameters.at("chain");
      const int first = varia::sdk::particle_index(ends.at(0), "chain"), last = varia::sdk::particle_index(ends.at(1), "chain");
      if (first >= last) throw std::invalid_argument("parameter 'chain' must be [first, last] with first < last, got " + ends.dump());
      for (int i = first; i < last; ++i) rods_.push_back({i, i + 1});
    } else if (parameters.contains("anchor") && parameters.contains("particle")) {
      rods_.push_back({varia::sdk::particle_index(parameters.at("particle"), "particle"), kAnchor});
    } else {
      throw std::invalid_argument("a rod needs 'between', 'chain', or 'anchor' and 'particle'");
    }
  }

  varia::Status bind(int n, int space_dim) noexcept override {
    return varia::sdk::guarded(error_, [&] { attach(n, space_dim); });
  }
  int size() const noexcept override { return static_cast<int>(rods_.size()); }
  int jacobian_pattern(const int** rows, const int** cols) const noexcept override {
    *rows = jacobian_rows_.data();
    *cols = jacobian_cols_.data();
    return static_cast<int>(jacobian_rows_.size());
  }
  int hessian_pattern(const int** rows, const int** cols) const noexcept override { return hessian_.entries(rows, cols); }

  varia::Status evaluate(const double* q, double* g, double* jacobian) noexcept override {
    const double scale = 1.0 / (length_ * length_);
    int entry = 0;
    for (std::size_t k = 0; k < rods_.size(); ++k) {
      double squared = 0.0;
      for (int a = 0; a < d_; ++a) {
        const double offset = difference(q, rods_[k], a);
        squared += offset * offset;
        if (jacobian == nullptr) continue;
        jacobian[entry + a] = offset * scale;
        if (rods_[k][1] != kAnchor) jacobian[entry + d_ + a] = -offset * scale;
      }
      entry += rods_[k][1] == kAnchor ? d_ : 2 * d_;
      if (g != nullptr) g[k] = 0.5 * (squared * scale - 1.0);
    }
    return nullptr;
  }
  bool quadratic() const noexcept override { return true; }  // |x_i - x_j|^2: a constant Hessian
  varia::Status weighted_hessian(const double*, const double* lambda, double* values) noexcept override {
    std::fill_n(values, hessian_.size(), 0.0);
    const double scale = 1.0 / (length_ * length_);
    for (std::size_t k = 0; k < rods_.size(); ++k)
      for (int e = 0; e < static_cast<int>(slots_[k].size()); ++e) values[slots_[k][e]] += signs_[k][e] * lambda[k] * scale;
    return nullptr;
  }

 private:
  // x_i - x_j (or x_i - anchor) in coordinate a.
  double difference(const double* q, const std::array<int, 2>& rod, int a) const {
    const double far = rod[1] == kAnchor ? anchor_[a] : q[rod[1] * d_ + a];
    return q[rod[0] * d_ + a] - far;
  }
  void attach(int n, int space_dim) {
    if (space_dim <= 0)
      throw std::invalid_argument("a rod joins particles: the system must be a particle system (composite)");
    d_ = space_dim;
    if (!anchor_.empty() && static_cast<int>(anchor_.size()) != d_)
      throw std::invalid_argument("parameter 'anchor' must have space_dim = " + std::to_string(d_) + " numbers, got " +
                                  std::to_string(anchor_.size()));
    const int particles = n / d_;
    for (std::size_t k = 0; k < rods_.size(); ++k) {
      std::vector<int> ends{rods_[k][0]};
      if (rods_[k][1] != kAnchor) ends.push_back(rods_[k][1]);
      for (int end : ends)
        if (end >= particles)
          throw std::invalid_argument("particle " + std::to_string(end) + " does not exist (the system has " +
                                      std::to_string(particles) + ")");
      for (int end : ends)
        for (int a = 0; a < d_; ++a) {
          jacobian_rows_.push_back(static_cast<int>(k));
          jacobian_cols_.push_back(end * d_ + a);
        }
      slots_.emplace_back();
      signs_.emplace_back();
      for (std::size_t u = 0; u < ends.size(); ++u)
        for (std::size_t w = 0; w < ends.size(); ++w)
          for (int a = 0; a < d_; ++a) {
            slots_[k].push_back(hessian_.slot(ends[u] * d_ + a, ends[w] * d_ + a));
            signs_[k].push_back(u == w ? 1.0 : -1.0);
          }
    }
  }

  double length_;
  std::vector<double> anchor_;
  std::vector<std::array<int, 2>> rods_;
  int d_ = 0;
  std::vector<int> jacobian_rows_, jacobian_cols_;
  varia::SparsePattern hessian_;
  std::vector<std::vector<int>> slots_;  // each rod's Hessian entries' slots, with their signs
  std::vector<std::vector<double>> signs_;
  std::string error_;
};

}  // namespace

VARIA_PLUGIN(Rod, constraint, rod)
