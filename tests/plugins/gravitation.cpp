// The gravitation effect (plugins/effect/gravitation.cpp): V against the pairwise sum written here;
// two bodies under it move relative to each other on the Kepler orbit of mu = G (m1 + m2) (the
// kepler plugin's closed-form solution), at Galerkin's order; and the outer solar system of Hairer,
// Lubich & Wanner (sec. I.2.3) with Galerkin of degree 4 and 4 Gauss points at h = 100 days ends
// within the method's error of HLW's reference solution after 500000 days, where a method of order
// 4 does not.
#include <doctest/doctest.h>

#include <Eigen/Core>
#include <cmath>
#include <memory>
#include <vector>

#include "../core/fixtures.hpp"
#include "load_plugin.hpp"
#include "varia/core/composite.hpp"
#include "varia/core/galerkin.hpp"

namespace {

using varia::test::rn;

using Eigen::VectorXd;
using Json = nlohmann::json;

std::shared_ptr<varia::CompositeLagrangian> gravitating(int space_dim, const std::vector<double>& masses,
                                                        const Json& parameters) {
  const int n = space_dim * static_cast<int>(masses.size());
  auto effect = varia::test::load_plugin("effect", "gravitation").create<varia::Effect>(parameters, rn(n));
  return std::make_shared<varia::CompositeLagrangian>(space_dim, masses,
                                                      std::vector<std::shared_ptr<varia::Effect>>{effect});
}

// (q, p) after `steps` Galerkin steps of degree s with s Gauss-Legendre points (the s-stage Gauss
// method) from (q, m v).
VectorXd gauss(varia::Lagrangian& lagrangian, int s, const VectorXd& q0, const VectorXd& p0, double h, long steps) {
  const int n = static_cast<int>(q0.size());
  varia::testing::FlatSpace space(n);
  const auto rule = varia::test::load_plugin("quadrature", "gauss_legendre").create<varia::Quadrature>({{"points", s}});
  varia::GalerkinDiscreteLagrangian map(space, lagrangian, *rule, varia::equispaced_control_times(s),
                                        varia::SolverOptions{});
  VectorXd q = q0, p = p0, q1(n), p1(n);
  map.advance(q.data(), p.data(), h, steps, q1.data(), p1.data());
  VectorXd state(2 * n);
  state << q, p;  // advance() steps (q, p) in place; (q1, p1) are its workspace
  return state;
}

}  // namespace

TEST_CASE("gravitation: V = -G sum_{i<j} m_i m_j / sqrt(|x_i - x_j|^2 + eps^2) over every pair") {
  const std::vector<double> masses{1.0, 2.0, 0.5, 3.0};
  const VectorXd q = (VectorXd(8) << 0.1, 0.2, 1.3, -0.4, -0.7, 0.9, 2.0, 1.1).finished();
  for (double eps : {0.0, 0.3}) {
    const auto L = gravitating(2, masses, {{"G", 0.7}, {"softening", eps}});
    double V = 0.0;
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j)
        V -= 0.7 * masses[i] * masses[j] / std::hypot(q(2 * i) - q(2 * j), q(2 * i + 1) - q(2 * j + 1), eps);
    double value = 0.0;
    const VectorXd v = VectorXd::Zero(8);
    REQUIRE(L->evaluate(q.data(), v.data(), &value, nullptr, nullptr) == nullptr);
    CHECK(value == doctest::Approx(-V).epsilon(1e-15));  // L = T - V, T = 0
  }
}

TEST_CASE("gravitation: two bodies move relative to each other on the Kepler orbit of mu = G (m1 + m2), at "
          "order 6 with the 3-stage Gauss method") {
  const double G = 0.8, m1 = 1.5, m2 = 0.5, mu = G * (m1 + m2);
  const auto L = gravitating(2, {m1, m2}, {{"G", G}});
  // Relative position r = x1 - x2 and velocity w on an orbit of eccentricity about 0.5; the centre of
  // mass at rest at the origin.
  const VectorXd r0 = (VectorXd(2) << 1.0, 0.0).finished(), w0 = (VectorXd(2) << 0.0, std::sqrt(1.5 * mu)).finished();
  VectorXd q0(4), p0(4);
  q0 << m2 / (m1 + m2) * r0, -m1 / (m1 + m2) * r0;
  p0 << m1 * m2 / (m1 + m2) * w0, -m1 * m2 / (m1 + m2) * w0;
  const double T = 10.0;
  auto kepler = varia::test::load_plugin("lagrangian", "kepler").create<varia::Lagrangian>({{"mu", mu}}, rn(2));
  VectorXd r(2), w(2);
  REQUIRE(kepler->exact_solution(r0.data(), w0.data(), T, r.data(), w.data()) == nullptr);
  double errors[2];
  for (int k = 0; k < 2; ++k) {
    const double h = 0.05 / (1 << k);
    const VectorXd x = gauss(*L, 3, q0, p0, h, std::lround(T / h));
    errors[k] = (x.segment<2>(0) - x.segment<2>(2) - r).lpNorm<Eigen::Infinity>();
  }
  MESSAGE("relative position error at T = 10: " << errors[0] << " (h = 0.05), " << errors[1] << " (h = 0.025), order "
                                                << std::log2(errors[0] / errors[1]));
  CHECK(errors[1] < 1e-8);
  CHECK(std::log2(errors[0] / errors[1]) == doctest::Approx(6.0).epsilon(0.05));
}

TEST_SUITE("long") {
  TEST_CASE("the outer solar system (HLW I.2.3) with Galerkin of degree 4 and 4 Gauss points at h = 100 days ends "
            "within 1e-9 AU of HLW's reference after 500000 days and the 2-stage Gauss method does not") {
    // Jupiter, Saturn, Uranus, Neptune, Pluto, the Sun; AU, solar masses, days (HLW's data, the same as
    // Hairer's problem.f, IPROB 4, and scenes/effects/outer-solar-system.json).
    const std::vector<double> masses{0.000954786104043, 0.000285583733151, 0.0000437273164546, 0.0000517759138449,
                                     1.0 / 1.3e8, 1.00000597682};
    const auto L = gravitating(3, masses, {{"G", 2.95912208286e-4}});
    VectorXd q0(18), v0(18), p0(18), q_end(18);
    q0 << -3.5023653, -3.8169847, -1.5507963, 9.0755314, -3.0458353, -1.6483708, 8.3101420, -16.2901086, -7.2521278,
        11.4707666, -25.7294829, -10.8169456, -15.5387357, -25.2225594, -3.1902382, 0, 0, 0;
    v0 << 0.00565429, -0.00412490, -0.00190589, 0.00168318, 0.00483525, 0.00192462, 0.00354178, 0.00137102,
        0.00055029, 0.00288930, 0.00114527, 0.00039677, 0.00276725, -0.00170702, -0.00136504, 0, 0, 0;
    // HLW's reference solution at t = 500000 (problem.f's QEX; gni_irk2 with 4 stages at h = 12.5 ends
    // within 1.6e-12 of it).
    q_end << 7.766584086800482, 0.2531065754551048, -0.09410571402013185, -5.564967162844037, 1.674849740822012,
        0.9767232069533176, 19.63899572895227, 8.958504552286460, 3.611839157057347, 24.93570870305177,
        17.69518676153705, 6.583785164549242, 31.78592511375764, 38.63618958160644, 3.192794169732889,
        3.084118473380683, -1.227726356581642, -0.6162537634647217;
    for (int i = 0; i < 18; ++i) p0(i) = masses[i / 3] * v0(i);
    const double gauss4 = (gauss(*L, 4, q0, p0, 100.0, 5000).head(18) - q_end).lpNorm<Eigen::Infinity>();
    const double gauss2 = (gauss(*L, 2, q0, p0, 100.0, 5000).head(18) - q_end).lpNorm<Eigen::Infinity>();
    MESSAGE("max position error at t = 500000 days, h = 100: 4 stages (order 8) " << gauss4 << " AU, 2 stages (order 4) "
                                                                                  << gauss2 << " AU");
    CHECK(gauss4 < 1e-9);
    CHECK(gauss2 > 1e-6);
  }
}
