// The composite Lagrangian of a particle system (spec: "Composed systems: effects"): N particles
// in d dimensions, q = (x_0, ..., x_{N-1}) with x_i = q[i d .. i d + d), and
//   L(q, v) = 1/2 sum_i m_i |v_i|^2 - sum_e V_e(q),
// the potentials V_e being Effect objects (effect.hpp), each over the coordinates it names. The
// Hessian is sparse (hessian_pattern()): the diagonal mass block and the union of the effects'
// Hessian entries, so that a chain of springs has a banded Hessian.
// Built here, in core, from the masses and the effect objects: the host creates the effects from
// the scene's "terms" and hands them in; no plugin calls another.
#pragma once

#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "varia/abi/effect.hpp"
#include "varia/abi/lagrangian.hpp"
#include "varia/abi/sparse_pattern.hpp"

namespace varia {

class CompositeLagrangian : public Lagrangian {
 public:
  // Binds each effect to the system; throws std::invalid_argument whose message starts with the
  // parameter at fault, relative to the composite ("terms/2: ...", "masses: ...").
  CompositeLagrangian(int space_dim, std::vector<double> masses,
                      std::vector<std::shared_ptr<Effect>> effects);
  int position_size() const noexcept final { return n_; }
  int velocity_size() const noexcept final { return n_; }
  Status evaluate(const double* q, const double* v, double* value, double* gradient,
                  double* hessian) noexcept final;
  int hessian_pattern(const int** rows, const int** cols) const noexcept final;
  bool constant_mass_matrix(double* mass) const noexcept final;
  bool has_constant_mass_matrix() const noexcept final { return true; }  // diag(m_i), each repeated space_dim times
  int space_dim() const noexcept final { return d_; }
  // L and its gradient at jets, from the effects' (Effect::gradient_jet): the shooting
  // construction's field. Available when every effect evaluates at jets.
  bool evaluates_at_jets() const noexcept final;
  Status gradient_jet(const Jet2* q, const Jet2* v, Jet2* value, Jet2* gradient) noexcept final;

 private:
  // An effect's gathered coordinates and its gradient there, at one scalar.
  template <class T>
  struct Buffers {
    std::vector<T> x, gradient;
  };
  // One effect with its buffers and where its Hessian entries go in the pattern.
  struct Term {
    std::shared_ptr<Effect> effect;
    const int* indices = nullptr;
    std::vector<int> slots;
    Buffers<double> at_doubles;  // sized at bind
    Buffers<Jet2> at_jets;       // sized at the first evaluation at jets
    std::vector<double> hessian;
    template <class T>
    Buffers<T>& buffers() {
      if constexpr (std::is_same_v<T, double>)
        return at_doubles;
      else
        return at_jets;
    }
  };
  Term bind(std::shared_ptr<Effect> effect, std::size_t index);
  template <class T>
  void sum_terms(const T* q, const T* v, T* value, T* gradient, double* hessian);

  int d_, n_;
  std::vector<double> masses_;  // one per coordinate: m_i repeated d times
  std::vector<Term> terms_;
  SparsePattern pattern_;
  std::string error_;
};

}  // namespace varia
