// A force (abi/include/varia/abi/force.hpp), for force plugins: the system's sizes from the
// context, the Jacobian's pattern as the plugin declares its entries, and the boundary rule
// (exceptions become Status messages). docs/writing-effects.md has the walk-through, and
// varia-conformance checks the Jacobian (sdk/conformance/force.hpp).
#pragma once

#include <string>
#include <vector>

#include "varia/abi/force.hpp"
#include "varia/sdk/plugin.hpp"

namespace varia::sdk {

class ForceBase : public Force {
 public:
  explicit ForceBase(const Context& context) : m_(context.point_size), n_(context.dim) {}
  int position_size() const noexcept final { return m_; }
  int velocity_size() const noexcept final { return n_; }
  int jacobian_pattern(const int** rows, const int** cols) const noexcept final {
    *rows = rows_.data();
    *cols = cols_.data();
    return static_cast<int>(rows_.size());
  }
  Status evaluate(double t, const double* q, const double* v, double* force,
                  double* jacobian) noexcept final {
    return guarded(error_, [&] { apply(t, q, v, force, jacobian); });
  }

 protected:
  // f(t, q, v) and the Jacobian values in the order of add_entry's calls.
  virtual void apply(double t, const double* q, const double* v, double* force, double* jacobian) const = 0;
  // Declares the Jacobian entry (row, col) of [df/dq (m columns), df/dv (n columns)].
  void add_entry(int row, int col) {
    rows_.push_back(row);
    cols_.push_back(col);
  }
  int m_, n_;

 private:
  std::vector<int> rows_, cols_;
  std::string error_;
};

}  // namespace varia::sdk
