// A constraint that is not quadratic, for the host's tests: particle 0 of a particle system in
// three dimensions at unit distance from the origin, written as the quartic
//   g(q) = (|x|^4 - 1) / 4,   G = |x|^2 x^T,   Hessian of lambda g = lambda (|x|^2 I + 2 x x^T),
// whose zero set and normal direction are the unit rod's. So every construction that takes it moves
// the spherical pendulum as it does on the `rod` from the anchor at the origin (the multiplier
// differs by the factor |x|^2 = 1), and those that need quadratic constraints refuse it.
#include <cmath>

#include <varia/abi/constraint.hpp>
#include <varia/sdk/no_parameters.hpp>
#include <varia/sdk/plugin.hpp>

namespace {

class QuarticAnchor final : public varia::Constraint {
 public:
  static constexpr const char* version = "0.0.1";
  static constexpr const char* parameter_schema = varia::sdk::kNoParameters;
  static constexpr const char* properties = R"json({"fault": "none (tests only): a constraint that is not quadratic"})json";

  QuarticAnchor(const nlohmann::json& parameters, const varia::sdk::Context&) {
    varia::sdk::require_no_parameters(parameters, "quartic-anchor");
  }
  varia::Status bind(int n, int space_dim) noexcept override {
    return space_dim == 3 && n >= 3 ? nullptr : "quartic-anchor binds to particle 0 of particles in 3 dimensions";
  }
  int size() const noexcept override { return 1; }
  int jacobian_pattern(const int** rows, const int** cols) const noexcept override {
    *rows = kZeros;
    *cols = kAxes;
    return 3;
  }
  int hessian_pattern(const int** rows, const int** cols) const noexcept override {
    *rows = kHessianRows;
    *cols = kHessianCols;
    return 9;
  }
  varia::Status evaluate(const double* q, double* g, double* jacobian) noexcept override {
    const double r2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2];
    if (g != nullptr) g[0] = 0.25 * (r2 * r2 - 1.0);
    if (jacobian != nullptr)
      for (int k = 0; k < 3; ++k) jacobian[k] = r2 * q[k];
    return nullptr;
  }
  varia::Status weighted_hessian(const double* q, const double* lambda, double* values) noexcept override {
    const double r2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2];
    for (int e = 0; e < 9; ++e) {
      const int j = kHessianRows[e], k = kHessianCols[e];
      values[e] = lambda[0] * ((j == k ? r2 : 0.0) + 2.0 * q[j] * q[k]);
    }
    return nullptr;
  }

 private:
  static constexpr int kZeros[3] = {0, 0, 0};
  static constexpr int kAxes[3] = {0, 1, 2};
  static constexpr int kHessianRows[9] = {0, 0, 0, 1, 1, 1, 2, 2, 2};
  static constexpr int kHessianCols[9] = {0, 1, 2, 0, 1, 2, 0, 1, 2};
};

}  // namespace

VARIA_PLUGIN(QuarticAnchor, constraint, quartic_anchor)
