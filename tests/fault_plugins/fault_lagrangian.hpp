// A one-dimensional oscillator L = v^2/2 - q^2/2 whose evaluation is replaced by a fault of the
// test's choosing: the fault plugins of tests/fault_plugins (never bundled nor installed) derive
// from it, so that each differs from a good plugin in one way only. Its derivatives are written
// out by hand: these plugins test how the host survives a plugin, not automatic differentiation,
// and without the AD SDK each compiles in a second or two.
#pragma once

#include <varia/abi/lagrangian.hpp>
#include <varia/sdk/plugin.hpp>

namespace varia::test {

template <class Model>
class FaultLagrangian : public Lagrangian {
 public:
  static constexpr const char* version = "0.0.1";
  static constexpr const char* parameter_schema = R"({"type": "object", "additionalProperties": false})";
  static constexpr const char* properties = R"json({"symmetry": "none", "fault": "deliberate (tests only)"})json";

  int position_size() const noexcept final { return 1; }
  int velocity_size() const noexcept final { return 1; }

  // The oscillator's value, gradient [-q, v] and Hessian diag(-1, 1), each times the factor the
  // model's evaluation() returns (1 for a good value; it may also throw, crash or exit).
  Status evaluate(const double* q, const double* v, double* value, double* gradient,
                  double* hessian) noexcept final {
    return sdk::guarded(error_, [&] {
      const double factor = static_cast<Model&>(*this).evaluation();
      if (value != nullptr) *value = factor * (0.5 * v[0] * v[0] - 0.5 * q[0] * q[0]);
      if (gradient != nullptr) gradient[0] = -factor * q[0], gradient[1] = factor * v[0];
      if (hessian != nullptr) hessian[0] = -factor, hessian[1] = hessian[2] = 0.0 * factor, hessian[3] = factor;
    });
  }

  // The good oscillator, for models whose fault lies elsewhere.
  double evaluation() { return 1.0; }

 private:
  std::string error_;  // the message of the last failed call
};

// The oscillator until its evaluation number `after` (a parameter, 0 by default), which runs
// Model::fault() (a crash, an exit): a run then has rows written, and rows buffered, before it.
template <class Model>
class FaultAfter : public FaultLagrangian<Model> {
 public:
  static constexpr const char* parameter_schema =
      R"({"type": "object", "properties": {"after": {"type": "integer", "minimum": 0, "default": 0}},
          "additionalProperties": false})";

  explicit FaultAfter(const nlohmann::json& parameters) : after_(parameters.value("after", 0L)) {}

  double evaluation() {
    if (evaluations_++ == after_) Model::fault();
    return 1.0;
  }

 private:
  long after_;
  long evaluations_ = 0;
};

}  // namespace varia::test
