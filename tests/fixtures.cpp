// The test fixtures compiled once, linked into every test program as the test_fixtures library:
// the models (tests/core/fixtures.hpp and shooting_fixtures.hpp declare these instantiations
// extern) and the Gauss-Legendre rules.
#include "core/fixtures.hpp"
#include "core/shooting_fixtures.hpp"

#include <Eigen/Eigenvalues>

template class varia::sdk::AutodiffLagrangian<varia::testing::Oscillator, 1, 1>;
template class varia::sdk::AutodiffLagrangian<varia::testing::Pendulum, 1, 1>;
template class varia::sdk::AutodiffLagrangian<varia::testing::Pendulums<>, Eigen::Dynamic, Eigen::Dynamic>;
template class varia::sdk::AutodiffLagrangian<varia::testing::Top, 9, 3>;
template class varia::sdk::AutodiffLagrangian<varia::testing::PlanarKepler, 2, 2>;
template class varia::sdk::AutodiffLagrangian<varia::testing::DoublePendulum, 2, 2>;

// The s-point Gauss-Legendre rule on [0, 1] (Golub & Welsch: the nodes are the eigenvalues of the
// Jacobi matrix of the Legendre recurrence, the weights the squared first components of its
// eigenvectors).
varia::testing::FixedRule varia::testing::gauss_legendre(int s) {
  Eigen::MatrixXd jacobi = Eigen::MatrixXd::Zero(s, s);
  for (int k = 1; k < s; ++k) jacobi(k, k - 1) = jacobi(k - 1, k) = k / std::sqrt(4.0 * k * k - 1.0);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(jacobi);
  std::vector<double> c(s), b(s);
  for (int i = 0; i < s; ++i) {
    c[i] = (1.0 + eigen.eigenvalues()[i]) / 2;
    b[i] = eigen.eigenvectors()(0, i) * eigen.eigenvectors()(0, i);
  }
  return FixedRule(c, b, 2 * s - 1);
}
