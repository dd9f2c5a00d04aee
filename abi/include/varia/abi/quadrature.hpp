// Quadrature rule on [0, 1]: int_0^1 f(t) dt ~= sum_i b_i f(c_i)  (paper, sec. 2: nodes c_i, weights b_i).
// Rules whose nodes include 0 and 1 with zero weights are allowed (paper, sec. 3).
#pragma once

#include "varia/abi/plugin_object.hpp"

namespace varia {

class Quadrature : public PluginObject {
 public:
  Kind kind() const noexcept final { return Kind::quadrature; }
  virtual int size() const noexcept = 0;                 // number of nodes
  virtual const double* nodes() const noexcept = 0;      // c_i in [0, 1], increasing
  virtual const double* weights() const noexcept = 0;    // b_i
  // Largest polynomial degree integrated exactly; the rule's order of accuracy is degree() + 1.
  virtual int degree() const noexcept = 0;
  // Symmetric: c_i + c_{n-1-i} = 1 and b_i = b_{n-1-i} (paper, sec. 3, self-adjointness).
  virtual bool symmetric() const noexcept = 0;
  // Endpoint derivative corrections (Euler-Maclaurin, paper sec. 3 "More general quadrature
  // formulas"): the rule adds sum_{k=1}^{K} h^{k+1} (a_k f^{(k)}(0) + z_k f^{(k)}(h)) to
  // h sum_i b_i f(c_i h). derivative_terms() is K (0 for ordinary rules); derivative_weights(k)
  // points to {a_k, z_k}.
  virtual int derivative_terms() const noexcept { return 0; }
  virtual const double* derivative_weights(int /*k*/) const noexcept { return nullptr; }
};

}  // namespace varia
