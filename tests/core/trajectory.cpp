// The trajectory driver (core/trajectory.hpp): the time travels with the state, so a run that
// starts at t0 from the state another run reached at t0 continues it to the bit, and a forced
// system sees the time of each step whoever steps it (the map keeps no clock).
#include "varia/core/trajectory.hpp"

#include <doctest/doctest.h>

#include "damped_drive.hpp"
#include "fixtures.hpp"
#include "wall.hpp"
#include "varia/core/galerkin.hpp"

namespace {

using namespace varia;
using namespace varia::testing;

struct DrivenOscillator {
  FlatSpace space{1};
  Oscillator oscillator;
  DampedDrive force;
  FixedRule rule = lobatto3();
  GalerkinDiscreteLagrangian map{space, oscillator, rule, equispaced_control_times(2), SolverOptions{}, {&force}};
};

const Eigen::VectorXd kQ0 = Eigen::VectorXd::Constant(1, 1.0), kP0 = Eigen::VectorXd::Zero(1);

TEST_CASE("a run started at t0 from the state another run reached at t0 continues it (to round-off: the "
          "compensated sums carry their remainders across steps, which a new run starts without)") {
  DrivenOscillator a, b;
  Trajectory whole(a.map, kQ0, kP0, 0.0, 0.05);
  whole.advance(40);
  const Eigen::VectorXd q = whole.q(), p = whole.p();
  whole.advance(40);
  Trajectory second_half(b.map, q, p, 2.0, 0.05);
  second_half.advance(40);
  CHECK(whole.t() == 4.0);
  CHECK(second_half.t() == 4.0);
  CHECK(second_half.q()(0) == doctest::Approx(whole.q()(0)).epsilon(1e-14));
  CHECK(second_half.p()(0) == doctest::Approx(whole.p()(0)).epsilon(1e-14));
  // Control: the same state stepped as if at t = 0 (no drive phase) ends elsewhere.
  Trajectory at_zero(b.map, q, p, 0.0, 0.05);
  at_zero.advance(40);
  CHECK(std::abs(at_zero.q()(0) - whole.q()(0)) > 1e-3);
}

TEST_CASE("the same map stepped by two trajectories in turn: each sees its own time (no clock in the map)") {
  DrivenOscillator a, reference;
  Trajectory first(a.map, kQ0, kP0, 0.0, 0.05), second(a.map, kQ0, kP0, 0.0, 0.05);
  Trajectory alone(reference.map, kQ0, kP0, 0.0, 0.05);
  for (int k = 0; k < 20; ++k) {
    first.step();
    second.step();
    alone.step();
  }
  // Equal up to round-off: the map warm-starts each step from the last one it took.
  CHECK(first.q()(0) == doctest::Approx(alone.q()(0)).epsilon(1e-12));
  CHECK(second.q()(0) == doctest::Approx(alone.q()(0)).epsilon(1e-12));
  CHECK(second.p()(0) == doctest::Approx(alone.p()(0)).epsilon(1e-12));
}

TEST_CASE("steps one by one and advance in one stretch take the same steps, to the bit") {
  DrivenOscillator a, b;
  Trajectory stepped(a.map, kQ0, kP0, 0.3, 0.05), advanced(b.map, kQ0, kP0, 0.3, 0.05);
  for (int k = 0; k < 25; ++k) stepped.step();
  advanced.advance(25);
  CHECK(stepped.steps() == 25);
  CHECK(advanced.t() == stepped.t());
  CHECK(stepped.q() == advanced.q());
  CHECK(stepped.p() == advanced.p());
}

TEST_CASE("a stretch that fails is stepped again one step at a time: the failure names its step, the state is "
          "the last good one") {
  FlatSpace space(1);
  Wall wall;
  FixedRule rule = trapezoid();
  const auto map = [&] { return GalerkinDiscreteLagrangian(space, wall, rule, equispaced_control_times(1), {}); };
  auto a = map(), b = map(), c = map();
  const Eigen::VectorXd p0 = Eigen::VectorXd::Constant(1, 0.2);
  Trajectory one_by_one(a, kP0, p0, 0.0, 0.5), checked(b, kP0, p0, 0.0, 0.5), plain(c, kP0, p0, 0.0, 0.5);
  long failed = -1;
  try {
    for (int k = 0; k < 100; ++k) one_by_one.step();
  } catch (const StepFailure& e) {
    failed = e.step();
  }
  REQUIRE(failed > 2);
  CHECK_THROWS_AS(checked.advance_checked(100), StepFailure);
  try {
    Trajectory again(b, kP0, p0, 0.0, 0.5);
    again.advance_checked(100);
  } catch (const StepFailure& e) {
    CHECK(e.step() == failed);
  }
  CHECK(checked.steps() == failed - 1);
  CHECK(checked.q() == one_by_one.q());
  CHECK(checked.p() == one_by_one.p());
  // Where it must not hold: advance() alone names the stretch's last step.
  try {
    plain.advance(100);
  } catch (const StepFailure& e) {
    CHECK(e.step() == 100);
  }
}

}  // namespace
