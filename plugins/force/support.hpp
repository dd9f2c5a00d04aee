// What the force plugins share (core/include/varia/core/force.hpp): the system's sizes from the
// context, and the boundary rule (exceptions become Status messages).
#pragma once

#include <string>
#include <vector>

#include "varia/core/force.hpp"
#include "varia/sdk/plugin.hpp"

namespace varia::plugins {

class ForceBase : public Force {
 public:
  explicit ForceBase(const sdk::Context& context) : m_(context.point_size), n_(context.dim) {}
  int position_size() const noexcept final { return m_; }
  int velocity_size() const noexcept final { return n_; }
  int jacobian_pattern(const int** rows, const int** cols) const noexcept final {
    *rows = rows_.data();
    *cols = cols_.data();
    return static_cast<int>(rows_.size());
  }
  Status evaluate(double t, const double* q, const double* v, double* force,
                  double* jacobian) noexcept final {
    return sdk::guarded(error_, [&] { apply(t, q, v, force, jacobian); });
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

}  // namespace varia::plugins
