// R^n, the vector space of n = `dim` coordinates, as a manifold. As a Lie group it is R^n under
// translation, whose exponential is the identity, so the natural chart at q0 (paper, sec. 2,
// "Natural charts": psi_{q0}^{-1}(xi) = q0 exp(xi)) is affine:
//   retract: q = q0 + xi,    local: xi = q - q0.
// A point is any n finite numbers; points, tangent vectors and momenta all have n numbers.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>

#include "varia/abi/manifold.hpp"
#include "varia/sdk/plugin.hpp"

namespace {

// The `dim` parameter: an integer >= 1 (at most INT_MAX), 1 when absent.
int dim_parameter(const nlohmann::json& parameters) {
  for (const auto& item : parameters.items())
    if (item.key() != "dim")
      throw std::invalid_argument("Rn: unknown parameter '" + item.key() +
                                  "' (the only parameter is 'dim')");
  if (!parameters.contains("dim")) return 1;
  const auto& value = parameters.at("dim");
  const double dim = value.is_number() ? value.get<double>() : std::nan("");
  if (!(dim >= 1 && dim <= std::numeric_limits<int>::max() && dim == std::floor(dim)))
    throw std::invalid_argument("Rn: 'dim' must be an integer >= 1, got " + value.dump());
  return static_cast<int>(dim);
}

class Rn final : public varia::Manifold {
 public:
  static constexpr const char* version = "1.0.0";
  static constexpr const char* parameter_schema = R"({
    "$schema": "http://json-schema.org/draft-07/schema#",
    "type": "object",
    "properties": {
      "dim": {"type": "integer", "minimum": 1, "maximum": 2147483647, "default": 1,
              "description": "n, the number of coordinates"}
    },
    "additionalProperties": false
  })";
  // (The delimiter "json" lets the text contain ')"'.)
  static constexpr const char* properties = R"json({
    "group": "R^n (translations)",
    "chart": "affine"
  })json";

  Rn(const nlohmann::json& parameters, const varia::sdk::Context&)
      : n_(dim_parameter(parameters)) {}

  int point_size() const noexcept override { return n_; }
  int dim() const noexcept override { return n_; }
  varia::ManifoldStructure structure() const noexcept override { return varia::ManifoldStructure::vector_space; }

  varia::Status retract(const double* q0, const double* xi, double* q) noexcept override {
    for (int i = 0; i < n_; ++i) q[i] = q0[i] + xi[i];
    return nullptr;
  }

  varia::Status local(const double* q0, const double* q, double* xi) noexcept override {
    for (int i = 0; i < n_; ++i) xi[i] = q[i] - q0[i];
    return nullptr;
  }

  // The affine chart to second order: point q0 + eta + xi in (eta, xi), velocity xi_dot in
  // (xi, xi_dot); both linear, so their Hessians are zero.
  varia::Status chart(const double* q0, const double* xi, const double* xi_dot, varia::Derivatives point,
                      varia::Derivatives velocity) noexcept override {
    const long V = 2L * n_;
    for (long i = 0; i < n_; ++i) {
      if (point.value != nullptr) point.value[i] = q0[i] + xi[i];
      if (velocity.value != nullptr) velocity.value[i] = xi_dot[i];
      for (long a = 0; a < V; ++a) {
        if (point.gradient != nullptr) point.gradient[i * V + a] = a == i || a == n_ + i ? 1.0 : 0.0;
        if (velocity.gradient != nullptr) velocity.gradient[i * V + a] = a == n_ + i ? 1.0 : 0.0;
      }
    }
    for (double* hessian : {point.hessian, velocity.hessian})
      if (hessian != nullptr) std::fill_n(hessian, n_ * V * V, 0.0);
    return nullptr;
  }

  // The affine chart's inverse: xi = q - q0, gradient the identity, Hessian zero.
  varia::Status local_derivatives(const double* q0, const double* q, varia::Derivatives xi) noexcept override {
    for (long i = 0; i < n_; ++i) {
      if (xi.value != nullptr) xi.value[i] = q[i] - q0[i];
      if (xi.gradient != nullptr)
        for (long a = 0; a < n_; ++a) xi.gradient[i * n_ + a] = a == i ? 1.0 : 0.0;
    }
    if (xi.hessian != nullptr) std::fill_n(xi.hessian, static_cast<long>(n_) * n_ * n_, 0.0);
    return nullptr;
  }

  bool contains(const double* q, char* why, int why_size) noexcept override {
    for (int i = 0; i < n_; ++i) {
      if (std::isfinite(q[i])) continue;
      if (why != nullptr && why_size > 0)
        std::snprintf(why, static_cast<std::size_t>(why_size),
                      "coordinate %d of the R^%d point is not finite (%g)", i, n_, q[i]);
      return false;
    }
    return true;
  }

 private:
  int n_;
};

}  // namespace

VARIA_PLUGIN(Rn, manifold, Rn)
