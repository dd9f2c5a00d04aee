// A one-dimensional oscillator L = v^2/2 - q^2/2 whose Lagrangian is replaced by a fault of the
// test's choosing: the fault plugins of tests/fault_plugins (never bundled nor installed) derive
// from it, so that each differs from a good plugin in one way only.
#pragma once

#include <varia/sdk/autodiff_lagrangian.hpp>

namespace varia::test {

template <class Model>
class FaultLagrangian : public sdk::AutodiffLagrangian<Model> {
 public:
  static constexpr const char* version = "0.0.1";
  static constexpr const char* parameter_schema = R"({"type": "object", "additionalProperties": false})";
  static constexpr const char* properties = R"json({"symmetry": "none", "fault": "deliberate (tests only)"})json";

  FaultLagrangian() : sdk::AutodiffLagrangian<Model>(1, 1) {}

  // The good oscillator, for models whose fault lies elsewhere.
  template <class T>
  static T oscillator(const sdk::Vec<T>& q, const sdk::Vec<T>& v) {
    return 0.5 * v(0) * v(0) - 0.5 * q(0) * q(0);
  }
};

}  // namespace varia::test

namespace varia::test {

// The oscillator until its evaluation number `after` (a parameter, 0 by default), which runs
// Model::fault() (a crash, an exit): a run then has rows written, and rows buffered, before it.
template <class Model>
class FaultAfter : public FaultLagrangian<Model> {
 public:
  static constexpr const char* parameter_schema =
      R"({"type": "object", "properties": {"after": {"type": "integer", "minimum": 0, "default": 0}},
          "additionalProperties": false})";

  explicit FaultAfter(const nlohmann::json& parameters) : after_(parameters.value("after", 0L)) {}

  template <class T>
  T lagrangian(const sdk::Vec<T>& q, const sdk::Vec<T>& v) const {
    if (evaluations_++ == after_) Model::fault();
    return FaultLagrangian<Model>::oscillator(q, v);
  }

 private:
  long after_;
  mutable long evaluations_ = 0;
};

}  // namespace varia::test
