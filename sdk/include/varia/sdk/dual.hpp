// Dual numbers for forward-mode automatic differentiation (Eigen's AutoDiffScalar; nested once for
// second derivatives), and the seeding and reading of them that the SDK's Lagrangian adapters share
// (autodiff_lagrangian.hpp, termwise_lagrangian.hpp).
//
// A model is written once, templated on its scalar T, over vectors Vec<T>. Small systems (at most
// kStackVariables numbers) are differentiated in one pass by dual numbers whose derivative vectors
// have a fixed size or a fixed capacity, so that a Vec of them lives on the stack and an evaluation
// allocates nothing. Larger systems are differentiated in chunks of kChunkDirections directions at a
// time (ChunkDual, ChunkDual2); a Vec of those, like a Vec of doubles, has no capacity bound, and
// the adapter that evaluates them keeps it as a workspace sized once.
#pragma once

#include <Eigen/Core>
#include <type_traits>
#include <unsupported/Eigen/AutoDiff>

#include "varia/abi/jet.hpp"
#include "varia/sdk/jet_tangent.hpp"

namespace varia::sdk {

// Up to this many numbers m + n, a dense Lagrangian is differentiated in one pass (SE(3): 12 + 6).
inline constexpr int kStackVariables = 18;
// Above it, forward mode takes this many derivative directions per pass (a gradient: k / 8 passes
// of the model; a Hessian: one pass per pair of chunks).
inline constexpr int kChunkDirections = 8;
// First derivatives at jet inputs (Lagrangian::gradient_jet) are taken kJetDirections numbers of
// (q, v) at a time, one evaluation per block: a dual number over jets then holds 1 + 4 jets. A
// model of sizes given at compile time (at most 12 numbers) keeps a Vec of them on the stack; one
// of sizes read at run time keeps them in a workspace sized once (ChunkJetDual), at any size.
inline constexpr int kJetDirections = 4;
// L's Hessian at jet inputs (Lagrangian::hessian_jet) is taken kHessianJetDirections by
// kHessianJetDirections numbers of (q, v) at a time, at jets of up to kMaxHessianJetVariables
// variables (FixedJet: a second-order scalar over FixedJet<6> holds 9 x 43 doubles), at any
// number of (q, v).
inline constexpr int kHessianJetDirections = 2;
inline constexpr int kMaxHessianJetVariables = 6;
// The shooting construction's shot runs inside the plugin (kernel::ExplicitShot) with fixed-size jets
// of 2n variables for n <= kMaxShotDimension, and explicit methods of at most kMaxShotStages stages
// (its workspace on the stack); other plans take the core's generic propagation.
inline constexpr int kMaxShotDimension = 3;
inline constexpr int kMaxShotStages = 8;

// A vector of at most `Capacity` numbers, stored in place.
template <class T, int Capacity>
using Bounded = Eigen::Matrix<T, Eigen::Dynamic, 1, 0, Capacity, 1>;

using Dual = Eigen::AutoDiffScalar<Bounded<double, kStackVariables>>;
using Dual2 = Eigen::AutoDiffScalar<Bounded<Dual, kStackVariables>>;
// The fixed-size counterparts for K variables (unrolled arithmetic; a second-order scalar holds
// (K+1)^2 doubles instead of 19^2).
template <int K>
using FixedDual = Eigen::AutoDiffScalar<Eigen::Matrix<double, K, 1>>;
template <int K>
using FixedDual2 = Eigen::AutoDiffScalar<Eigen::Matrix<FixedDual<K>, K, 1>>;
// A dual number over jets J (Jet2, or FixedJet<N> for jets of N variables) with K derivative
// directions.
template <int K, class J = Jet2>
using JetDual = Eigen::AutoDiffScalar<Eigen::Matrix<J, K, 1>>;
// The dual number over jets of models whose sizes are read at run time: kJetDirections directions
// (fewer in the last block), a type of its own whose Vec holds any number of inputs.
using ChunkJetDual = Eigen::AutoDiffScalar<Bounded<Jet2, kJetDirections>>;
// The second-order scalar of L's Hessian at jets of N variables: forward over forward mode with jet
// values (jet_tangent.hpp), kHessianJetDirections directions at each level; for models whose sizes
// are given at compile time, so that a Vec of them lives on the stack.
template <int N>
using HessianJetDual = Eigen::AutoDiffScalar<
    Eigen::Matrix<JetTangent<FixedJet<N>, kHessianJetDirections>, kHessianJetDirections, 1>>;
// The same for models whose sizes are read at run time: a type of its own (its outer directions
// capacity-bounded), whose Vec holds any number of inputs, kept in a workspace sized once.
using ChunkHessianJetDual = Eigen::AutoDiffScalar<
    Bounded<JetTangent<FixedJet<kMaxHessianJetVariables>, kHessianJetDirections>, kHessianJetDirections>>;
// The large systems' dual numbers: kChunkDirections directions (fewer in the last chunk).
using ChunkDual = Eigen::AutoDiffScalar<Bounded<double, kChunkDirections>>;
using ChunkDual2 = Eigen::AutoDiffScalar<Bounded<ChunkDual, kChunkDirections>>;
// Hessian-vector products of the large systems: kChunkDirections outer directions over one inner
// direction, fixed sizes (unrolled; the capacity-bounded ChunkDual2 with one inner direction costs
// as much a pass as with eight).
using ChunkProductDual = Eigen::AutoDiffScalar<Eigen::Matrix<FixedDual<1>, kChunkDirections, 1>>;
static_assert(kChunkDirections != kStackVariables, "the chunk duals must be types of their own (see Vec)");

// Whether a Vec of T has the stack capacity kStackVariables: every scalar but the value type and
// the chunk duals, whose vectors hold any number of inputs.
template <class T>
struct OnStack : std::true_type {};
template <>
struct OnStack<double> : std::false_type {};
template <>
struct OnStack<ChunkDual> : std::false_type {};
template <>
struct OnStack<ChunkDual2> : std::false_type {};
template <>
struct OnStack<ChunkJetDual> : std::false_type {};
template <>
struct OnStack<ChunkProductDual> : std::false_type {};
template <>
struct OnStack<ChunkHessianJetDual> : std::false_type {};

// The vectors q and v a model's lagrangian<T>(q, v) takes.
template <class T>
using Vec = Eigen::Matrix<T, Eigen::Dynamic, 1, 0, OnStack<T>::value ? kStackVariables : Eigen::Dynamic, 1>;

// The first-order variable x along direction `direction` of `size` (none when direction is
// outside [0, size)). X is double, or a jet for a dual number over jets.
template <class D, class X>
void seed(D& z, const X& x, int size, int direction) {
  z.value() = x;
  z.derivatives().setZero(size);
  if (direction >= 0 && direction < size) z.derivatives()(direction) = 1.0;
}

// The second-order variable x: first derivatives along `inner` of `inner_size` directions, the
// outer derivatives along `outer` of `outer_size` (forward over forward: the outer derivatives'
// own derivatives are the second derivatives).
template <class D2>
void seed(D2& z, double x, int inner_size, int inner, int outer_size, int outer) {
  seed(z.value(), x, inner_size, inner);
  z.derivatives().resize(outer_size);
  for (int j = 0; j < outer_size; ++j) seed(z.derivatives()(j), j == outer ? 1.0 : 0.0, inner_size, -1);
}

// Derivative i of a result (zero when the result does not depend on the inputs: an expression of
// constants leaves a dynamic derivative vector empty).
template <class D>
typename D::Scalar derivative(const D& r, int i) {
  if (r.derivatives().size() > i) return r.derivatives()(i);
  return typename D::Scalar(0.0);
}
// The second derivative of a second-order result along outer direction j and inner direction i.
template <class D2>
double second_derivative(const D2& r, int j, int i) {
  return r.derivatives().size() > j ? derivative(r.derivatives()(j), i) : 0.0;
}

}  // namespace varia::sdk

