// The test fixtures' models compiled once (tests/core/fixtures.hpp and shooting_fixtures.hpp
// declare these instantiations extern), linked into every test program as the test_fixtures
// library.
#include "core/fixtures.hpp"
#include "core/shooting_fixtures.hpp"

template class varia::sdk::AutodiffLagrangian<varia::testing::Oscillator, 1, 1>;
template class varia::sdk::AutodiffLagrangian<varia::testing::Pendulum, 1, 1>;
template class varia::sdk::AutodiffLagrangian<varia::testing::Pendulums<>, Eigen::Dynamic, Eigen::Dynamic>;
template class varia::sdk::AutodiffLagrangian<varia::testing::Top, 9, 3>;
template class varia::sdk::AutodiffLagrangian<varia::testing::PlanarKepler, 2, 2>;
template class varia::sdk::AutodiffLagrangian<varia::testing::DoublePendulum, 2, 2>;
