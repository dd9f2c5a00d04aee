// A non-conservative force f(t, q, v) (a covector, n = dim numbers) on any system. It enters the
// discrete equations through the discrete Lagrange-d'Alembert principle (Marsden & West 2001,
// sec. 3.2): D2 L_d(q_{k-1}, q_k) + D1 L_d(q_k, q_{k+1}) + f_d^+(q_{k-1}, q_k) + f_d^-(q_k, q_{k+1})
// = 0, with the discrete forces f_d^± taken through the construction's quadrature.
#pragma once

#include <vector>

#include "varia/abi/plugin_object.hpp"

namespace varia {

class Force : public PluginObject {
 public:
  Kind kind() const noexcept final { return Kind::force; }
  virtual int position_size() const noexcept = 0;  // m
  virtual int velocity_size() const noexcept = 0;  // n: the size of f
  // The stored entries of the n x (m + n) Jacobian [df/dq, df/dv], as (row, col) indices.
  virtual int jacobian_pattern(const int** rows, const int** cols) const noexcept = 0;
  // f(t, q, v) (n numbers) and the Jacobian values, one per pattern entry (may be null).
  virtual Status evaluate(double t, const double* q, const double* v, double* force,
                          double* jacobian) noexcept = 0;
};

// The sum of a system's forces, as the constructions evaluate it: every call checked (a failing
// force is a PluginFault, a non-finite one a NumericalFailure) and counted; the Jacobian pattern
// is the concatenation of the forces' patterns (an entry may repeat: consumers add the values).
class Forces {
 public:
  Forces(std::vector<Force*> forces, int position_size, int velocity_size);
  bool empty() const { return forces_.empty(); }
  // f = sum of the forces (n numbers); the Jacobian values per entry of rows()/cols() (may be null).
  void evaluate(double t, const double* q, const double* v, double* force, double* jacobian);
  const std::vector<int>& rows() const { return rows_; }
  const std::vector<int>& cols() const { return cols_; }
  long evaluations() const { return evaluations_; }

 private:
  std::vector<Force*> forces_;
  std::vector<int> offsets_;  // where each force's Jacobian values start
  std::vector<int> rows_, cols_;
  std::vector<double> one_;  // one force's value
  long evaluations_ = 0;
};

}  // namespace varia
