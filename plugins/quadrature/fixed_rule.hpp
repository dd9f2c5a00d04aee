// A quadrature rule with fixed nodes and weights and no parameters (midpoint, trapezoid,
// Simpson): what those plugins share. Paper, sec. 2: nodes c_i, weights b_i on [0, 1].
#pragma once

#include <array>

#include "varia/abi/quadrature.hpp"
#include "varia/sdk/no_parameters.hpp"
#include "varia/sdk/plugin.hpp"

namespace varia::plugins {

template <int N>
class FixedRule : public Quadrature {
 public:
  static constexpr const char* version = "1.0.0";
  static constexpr const char* parameter_schema = sdk::kNoParameters;

  FixedRule(const char* type, const nlohmann::json& parameters, std::array<double, N> nodes,
            std::array<double, N> weights, int degree)
      : nodes_(nodes), weights_(weights), degree_(degree) {
    sdk::require_no_parameters(parameters, type);
  }
  int size() const noexcept final { return N; }
  const double* nodes() const noexcept final { return nodes_.data(); }
  const double* weights() const noexcept final { return weights_.data(); }
  int degree() const noexcept final { return degree_; }
  bool symmetric() const noexcept final { return true; }  // all three are

 private:
  std::array<double, N> nodes_, weights_;
  int degree_;
};

}  // namespace varia::plugins
