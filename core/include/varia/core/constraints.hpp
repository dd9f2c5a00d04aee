// Holonomic constraints g(q) = 0 in the discrete variational principle (docs/constraints.md).
// What every construction that takes constraints shares, in one place:
//   - HolonomicConstraints: the system's constraint plugins (abi/constraint.hpp) as one g of m rows,
//     its Jacobian G (m x n) and the Hessian of sum_i lambda_i g_i (n x n), sparse with fixed
//     patterns, counted and checked;
//   - FixedPatternMatrix: a sparse matrix whose entries are named once (slots) and whose values are
//     written in place at every Newton iteration, factorized by a dense LU sized once (small
//     systems: nothing allocated) or Eigen's SparseLU with the symbolic analysis done once: the Newton Jacobian of the constrained equations (a construction's own
//     Jacobian bordered by the multipliers' blocks, -G^T and G) and the projection below;
//   - CotangentProjection: the momenta onto the constraint's cotangent space, p1 = p~ - G(q1)^T mu
//     with G(q1) M^{-1} p1 = 0 (the hidden constraint, for a constant mass matrix M): the saddle
//     point system [M G^T; G 0] [v; mu] = [p~; 0], v the velocity.
#pragma once

#include <Eigen/Core>
#include <Eigen/QR>
#include <Eigen/SparseCore>
#include <memory>
#include <stdexcept>
#include <vector>

#include "varia/abi/constraint.hpp"

namespace varia {

// A construction's refusal of the system's constraints with the rest of what the scene chose (a
// method, a form, forces): the host reports it at the constraints (spec: /system/constraints).
struct ConstraintsRefused : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

class HolonomicConstraints {
 public:
  // The constraints, each already bound to the system of n coordinates.
  HolonomicConstraints(std::vector<Constraint*> constraints, int n);
  int size() const { return m_; }
  int dim() const { return n_; }
  // Whether every constraint declares itself quadratic (Constraint::quadratic: a constant Hessian).
  bool quadratic() const;
  // Whether every constraint gives the derivatives of c_i = v^T H_i(q) v in q
  // (Constraint::curvature_derivative; every quadratic one does: they are zero).
  bool gives_curvature_derivative() const;
  // g(q), m numbers.
  void values(const double* q, double* g);
  // G(q) into jacobian() (and g(q) into g when not null).
  void evaluate_jacobian(const double* q, double* g = nullptr);
  const Eigen::SparseMatrix<double, Eigen::RowMajor>& jacobian() const { return jacobian_; }
  // The Hessian of sum_i lambda_i g_i at q into hessian().
  void evaluate_hessian(const double* q, const double* lambda);
  const Eigen::SparseMatrix<double>& hessian() const { return hessian_; }
  // dc_i/dq_j at (q, v), c_i = v^T H_i(q) v, into curvature_derivative() (m x n, G's pattern).
  void evaluate_curvature_derivative(const double* q, const double* v);
  const Eigen::SparseMatrix<double, Eigen::RowMajor>& curvature_derivative() const { return curvature_derivative_; }
  // max_i |g_i(q)| and max_i |(G(q) v)_i|: the observables `constraint` and `constraint_velocity`.
  double residual(const double* q);
  double velocity_residual(const double* q, const double* v);

 private:
  struct Part {
    Constraint* constraint;
    int first_row;
    std::vector<int> jacobian_slots, hessian_slots;  // where each of its entries goes in the values
    Eigen::VectorXd jacobian_values, hessian_values;
  };
  template <class Call>
  void gather(Eigen::SparseMatrix<double, Eigen::RowMajor>& into, const char* call, const char* what, Call&& values_of);

  std::vector<Part> parts_;
  int n_, m_ = 0;
  Eigen::SparseMatrix<double, Eigen::RowMajor> jacobian_, curvature_derivative_;
  Eigen::SparseMatrix<double> hessian_;
  Eigen::VectorXd g_;
};

// An orthonormal basis of ker G(q), the tangent space at q of the constraint manifold (n x (n - m)
// numbers): the last columns of the Householder QR of G(q)^T. Sized once: at() allocates nothing.
class TangentBasis {
 public:
  explicit TangentBasis(HolonomicConstraints& constraints);
  // Evaluates G(q); the basis stays valid until the next call.
  const Eigen::MatrixXd& at(const double* q);

 private:
  HolonomicConstraints& constraints_;
  Eigen::MatrixXd normals_, basis_;  // G^T, the basis
  Eigen::HouseholderQR<Eigen::MatrixXd> qr_;
  Eigen::VectorXd workspace_;
};

// A square sparse matrix of a fixed pattern: entries are named (slot) while it is being set up,
// then finish() fixes the pattern; values are set by slot, and factorize() runs a dense LU with
// partial pivoting (up to 32 rows: sized once, it allocates nothing) or SparseLU's numeric
// factorization (the symbolic analysis once; it allocates its workspace at every call).
class FixedPatternMatrix {
 public:
  FixedPatternMatrix();
  ~FixedPatternMatrix();
  void reset(int size);
  int slot(int row, int col);  // while setting up; the same (row, col) gives the same slot
  void finish();
  bool ready() const { return ready_; }
  void zero() { std::fill_n(matrix_.valuePtr(), matrix_.nonZeros(), 0.0); }
  double& at(int slot) { return matrix_.valuePtr()[positions_[slot]]; }
  // Throws NumericalFailure (naming `what`) when the matrix is singular.
  void factorize(const char* what);
  void solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& out);
  int size() const { return static_cast<int>(matrix_.rows()); }

 private:
  std::vector<Eigen::Triplet<double>> entries_;
  std::vector<int> positions_;
  Eigen::SparseMatrix<double> matrix_;
  void factorize_dense(const char* what);
  struct Factorization;  // the dense or the sparse LU (constraints.cpp)
  std::unique_ptr<Factorization> lu_;
  bool ready_ = false, analyzed_ = false;
};

// The hidden constraint G(q) M^{-1} p = 0 for a constant mass matrix M (given by its stored entries):
// p - G(q)^T mu is the momentum M v of the velocity v with M v + G^T mu = p, G v = 0.
class CotangentProjection {
 public:
  // M's entries (row, col, value), constant.
  CotangentProjection(HolonomicConstraints& constraints, const std::vector<Eigen::Triplet<double>>& mass);
  // correction = -G(q)^T mu for p as above (p + correction is the projected momentum); G(q) is
  // evaluated here.
  void correction(const double* q, const double* p, double* correction);
  // The velocity M^{-1} p of the last projection's momentum.
  const Eigen::VectorXd& velocity() const { return velocity_; }

 private:
  HolonomicConstraints& constraints_;
  FixedPatternMatrix saddle_;
  std::vector<int> transposed_slots_, slots_;  // each G entry's slot at (col, n + row) and (n + row, col)
  Eigen::VectorXd rhs_, solution_, velocity_;
};

}  // namespace varia
