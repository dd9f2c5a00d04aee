// What the Lagrangian plugins on Rn share: reading a positive parameter, refusing a manifold they
// do not support, and writing the constant mass matrix c I of L = c/2 |v|^2 - V(q).
#pragma once

#include <limits>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

#include "varia/sdk/plugin.hpp"

namespace varia::plugins {

// parameters[key] if present (it must be a number > 0), else `fallback`. The host has already
// checked the schema; this keeps a plugin made directly (tests, other hosts) just as safe.
inline double positive_parameter(const nlohmann::json& parameters, const char* key,
                                 double fallback) {
  if (!parameters.contains(key)) return fallback;
  const auto& value = parameters.at(key);
  if (!value.is_number() || !(value.get<double>() > 0))
    throw std::invalid_argument(std::string("parameter '") + key + "' must be a number > 0, got " +
                                value.dump());
  return value.get<double>();
}

// No upper bound on the dimension (require_rn).
inline constexpr int kAnyDim = std::numeric_limits<int>::max();

// Throws unless the manifold is Rn with min_dim <= dim <= max_dim, naming what `type` needs.
inline void require_rn(const sdk::Context& context, const char* type, int min_dim, int max_dim) {
  if (context.manifold == "Rn" && context.dim >= min_dim && context.dim <= max_dim) return;
  const std::string dims = min_dim == max_dim    ? std::to_string(min_dim)
                           : max_dim == kAnyDim ? ">= " + std::to_string(min_dim)
                                                : std::to_string(min_dim) + " to " + std::to_string(max_dim);
  throw std::invalid_argument(std::string(type) + " needs manifold Rn with dim " + dims + ", got " +
                              context.manifold + " with dim " + std::to_string(context.dim));
}

// Writes c I (n x n, column-major) into `out`.
inline void write_scaled_identity(double* out, int n, double c) noexcept {
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) out[j * n + i] = i == j ? c : 0.0;
}

}  // namespace varia::plugins
