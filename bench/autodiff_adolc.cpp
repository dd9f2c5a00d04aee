// varia's exact derivatives against ADOL-C (Debian's libadolc-dev, 2.7.2) on the planar Morse chain
// of N particles (default 30: 120 position and velocity numbers): the gradient and the Hessian by
// the morse-chain plugin (sdk::TermwiseLagrangian, fixed-size duals per term), by the same L as one
// dense sdk::AutodiffLagrangian (chunks of 8 directions), and by ADOL-C from one tape of L: reverse
// gradient(), dense hessian(), and the compressed sparse Hessian. docs/writing-plugins.md, section 2a,
// has the numbers and the choice they led to. Built only where ADOL-C is installed; it is not a
// dependency of varia. Usage: bench_autodiff_adolc [N]
#include <adolc/adolc.h>
#include <adolc/adolc_sparse.h>

#include <Eigen/Core>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "tests/sdk/morse_chain.hpp"
#include "varia/sdk/conformance/loader.hpp"

using Eigen::VectorXd;

// The mean time of f over as many calls as fit in 0.2 s (at least one), after one call.
template <class F>
double seconds_per_call(F&& f) {
  f();
  const auto start = std::chrono::steady_clock::now();
  for (long calls = 1;; ++calls) {
    f();
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (elapsed >= 0.2) return elapsed / calls;
  }
}

int main(int argc, char** argv) {
  const int particles = argc > 1 ? std::atoi(argv[1]) : 30;
  varia::testing::MorseChainParameters p;
  p.particles = particles;
  const int n = 2 * particles, k = 2 * n;
  VectorXd q, v;
  varia::testing::morse_chain_state(p, 1, q, v);
  VectorXd z(k);
  z << q, v;

  // ADOL-C: tape L(z) once.
  const short tag = 1;
  double L = 0.0;
  {
    trace_on(tag);
    std::vector<adouble> x(k);
    for (int i = 0; i < k; ++i) x[i] <<= z[i];
    const varia::plugins::MorseBond bond{};
    adouble l = 0.0;
    for (int i = n; i < k; ++i) l += 0.5 * x[i] * x[i];
    for (int i = 0; i + 3 < n; i += 2) l -= bond(x[i], x[i + 1], x[i + 2], x[i + 3]);
    l >>= L;
    trace_off();
  }
  std::vector<double> g(k);
  double** H = myalloc2(k, k);
  const double t_adolc_gradient = seconds_per_call([&] { gradient(tag, k, z.data(), g.data()); });
  const double t_adolc_dense = seconds_per_call([&] { hessian(tag, k, z.data(), H); });
  // Debian's ADOL-C is built without ColPack, so sparse_hess() is not available ("can only be used
  // if linked with ColPack"). The compressed Hessian by hand instead: hess_mat() with a colouring of
  // the chain's columns (particle j's coordinates by j mod 3, all velocities one colour: 7 colours),
  // then the entries read back from the pattern.
  const int colours = 7;
  const auto colour = [&](int i) { return i < n ? ((i / 2) % 3) * 2 + i % 2 : 6; };
  double** V = myalloc2(k, colours);
  double** W = myalloc2(k, colours);
  for (int i = 0; i < k; ++i)
    for (int c = 0; c < colours; ++c) V[i][c] = colour(i) == c ? 1.0 : 0.0;

  // varia: the bundled plugin, and the dense model of the same L.
  const varia::sdk::conformance::LoadedPlugin plugin(std::string(VARIA_BUILD_DIR) +
                                                     "/lib/varia/plugins/lagrangian_morse_chain.so");
  const auto chain =
      plugin.create<varia::Lagrangian>(nlohmann::json::object(), {{"manifold", "Rn"}, {"point_size", n}, {"dim", n}});
  varia::Lagrangian& termwise = *chain;
  const int *rows0 = nullptr, *cols0 = nullptr;
  const int entries0 = termwise.hessian_pattern(&rows0, &cols0);
  std::vector<double> compressed(entries0);
  const double t_adolc_sparse = seconds_per_call(
      [&] {
        hess_mat(tag, k, colours, z.data(), V, W);
        for (int e = 0; e < entries0; ++e) compressed[e] = W[rows0[e]][colour(cols0[e])];
      });
  const int nnz = entries0;
  varia::testing::DenseMorseChain dense(p);
  const int *rows = nullptr, *cols = nullptr;
  const int entries = termwise.hessian_pattern(&rows, &cols);
  std::vector<double> hv(entries), gv(k), Hd(k * k);
  double Lv = 0.0;
  const double t_termwise_hessian =
      seconds_per_call([&] { termwise.evaluate(q.data(), v.data(), &Lv, gv.data(), hv.data()); });
  const double t_termwise_gradient =
      seconds_per_call([&] { termwise.evaluate(q.data(), v.data(), nullptr, gv.data(), nullptr); });
  const double t_dense_hessian =
      seconds_per_call([&] { dense.evaluate(q.data(), v.data(), &Lv, gv.data(), Hd.data()); });
  const double t_dense_gradient =
      seconds_per_call([&] { dense.evaluate(q.data(), v.data(), nullptr, gv.data(), nullptr); });

  // Agreement: ADOL-C's dense Hessian (lower triangle) against varia's dense one.
  double gap = 0.0, gap_sparse = 0.0;
  for (int i = 0; i < k; ++i)
    for (int j = 0; j <= i; ++j) gap = std::max(gap, std::abs(H[i][j] - Hd[j * k + i]));
  for (int e = 0; e < nnz; ++e) gap_sparse = std::max(gap_sparse, std::abs(compressed[e] - Hd[cols0[e] * k + rows0[e]]));
  std::printf("Morse chain, %d particles, k = %d numbers; Hessian: %d stored entries (term-wise), %d (ADOL-C compressed, 7 colours)\n",
              particles, k, entries, nnz);
  std::printf("| method | gradient | Hessian (with gradient for varia) |\n|---|---|---|\n");
  std::printf("| varia TermwiseLagrangian (fixed-size duals per term) | %.2f us | %.2f us (sparse) |\n",
              1e6 * t_termwise_gradient, 1e6 * t_termwise_hessian);
  std::printf("| varia AutodiffLagrangian (chunks of 8 directions) | %.2f us | %.1f us (dense) |\n",
              1e6 * t_dense_gradient, 1e6 * t_dense_hessian);
  std::printf("| ADOL-C gradient() / hessian() | %.2f us | %.1f us (dense) |\n", 1e6 * t_adolc_gradient,
              1e6 * t_adolc_dense);
  std::printf("| ADOL-C hess_mat, 7 colours by hand (sparse_hess needs ColPack) | | %.2f us (sparse) |\n", 1e6 * t_adolc_sparse);
  std::printf("max |H_adolc - H_varia|: dense %.2e, sparse %.2e\n", gap, gap_sparse);
  return 0;
}
