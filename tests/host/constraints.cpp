// Holonomic constraints (spec: "Constrained systems, S2 and products"; docs/constraints.md): the
// spherical pendulum as one particle in R^3 on a rod from the origin, against an independent
// reference (Boost.Odeint's Runge-Kutta-Fehlberg 7(8) on the Cartesian equations with the
// multiplier in closed form, x'' = g - lambda x, lambda = (x . g + |x'|^2) / |x|^2), and what the
// host refuses.
#include <doctest/doctest.h>

#include <Eigen/LU>
#include <array>
#include <tuple>
#include <vector>
#include <boost/numeric/odeint.hpp>
#include <cmath>
#include <nlohmann/json.hpp>

#include "assemble.hpp"
#include "host/support.hpp"
#include "registry.hpp"
#include "run.hpp"
#include "scene.hpp"
#include "varia/core/trajectory.hpp"
#include "varia/core/verification.hpp"

namespace varia::host {
namespace {

using nlohmann::json;
using State6 = std::array<double, 6>;
constexpr double kGravity = 9.81;

json galerkin_lobatto(int degree) {
  return {{"construction", "galerkin"}, {"degree", degree}, {"quadrature", {{"type", "gauss-lobatto"}, {"points", degree + 1}}}};
}

// The spherical pendulum's scene (by default the particle on a rod) with `method`, `steps` steps of h.
json spherical_pendulum(const json& method, double h, long steps, const char* scene = "spherical-pendulum-rod-s1.json") {
  json document = json::parse(test::read_file(test::kSourceDir / "scenes/multibody" / scene));
  document["method"] = method;
  document["step"] = h;
  document.erase("t_end");
  document["steps"] = steps;
  return document;
}
json spherical_pendulum(int degree, double h, long steps) { return spherical_pendulum(galerkin_lobatto(degree), h, steps); }

Assembly assembled(const json& document, Registry& registry, Scene& scene) {
  scene = parse_scene(document);
  validate_parameters(scene, registry);
  return assemble(scene, registry);
}

// The state of y' = field(y) at time T from `start`, by RKF7(8) at tolerances 1e-15: the Cartesian
// references of the constrained motions below.
template <class State, class Field>
State integrated(State z, const Field& field, double T) {
  namespace odeint = boost::numeric::odeint;
  odeint::integrate_adaptive(odeint::make_controlled(1e-15, 1e-15, odeint::runge_kutta_fehlberg78<State>()), field, z,
                             0.0, T, 1e-3);
  return z;
}

// (x, x') at time T from (x0, v0), to about 1e-14.
State6 reference_state(const State6& start, double T) {
  const auto field = [](const State6& y, State6& dy, double) {
    const double lambda = (-kGravity * y[2] + y[3] * y[3] + y[4] * y[4] + y[5] * y[5]) /
                          (y[0] * y[0] + y[1] * y[1] + y[2] * y[2]);
    for (int a = 0; a < 3; ++a) dy[a] = y[3 + a], dy[3 + a] = -lambda * y[a];
    dy[5] -= kGravity;
  };
  return integrated(start, field, T);
}

// The spherical pendulum on a rod under `method` at four step sizes halving from h0 to T = 1: the
// largest errors in q and p against the RKF7(8) reference, and the order fitted to them. With
// `constraints`, those instead of the scene's rod (plugins also from the tests' own directory); with
// `scene`, that scene (the same pendulum: pendulum-chain on S2 with mass 1 and rod 1, M = I).
OrderFit spherical_pendulum_order(const json& method, double h0, const json& constraints = nullptr,
                                  const char* scene_name = "spherical-pendulum-rod-s1.json") {
  Registry registry{Registry::search_path({VARIA_FAULT_PLUGIN_DIR})};
  const double T = 1.0;
  std::vector<double> hs, errors;
  State6 truth{};
  for (double h = h0; hs.size() < 4; h /= 2) {
    Scene scene;
    json document = spherical_pendulum(method, h, std::lround(T / h), scene_name);
    if (!constraints.is_null()) document["system"]["constraints"] = constraints;
    Assembly a = assembled(document, registry, scene);
    if (hs.empty()) {
      for (int k = 0; k < 3; ++k) truth[k] = a.q0[k], truth[3 + k] = a.v0[k];
      truth = reference_state(truth, T);
    }
    Trajectory trajectory(*a.map, a.q0, a.p0, a.t0, h);
    trajectory.advance(scene.steps);
    double error = 0.0;  // m = 1: p = x'
    for (int k = 0; k < 3; ++k)
      error = std::max({error, std::abs(trajectory.q()[k] - truth[k]), std::abs(trajectory.p()[k] - truth[3 + k])});
    hs.push_back(h);
    errors.push_back(error);
  }
  const OrderFit fit = fit_order(hs, errors, 1e-12);
  MESSAGE(method.dump(), ": errors ", errors[0], " .. ", errors[3], ", fitted order ", fit.slope, " on ", fit.used,
          " points");
  return fit;
}

}  // namespace

TEST_CASE("the spherical pendulum on a rod: Galerkin s = 1, 2, 3 with s + 1 Lobatto points has orders 2, 4, 6") {
  for (int s = 1; s <= 3; ++s) {
    CAPTURE(s);
    const OrderFit fit = spherical_pendulum_order(galerkin_lobatto(s), std::array<double, 3>{0.02, 0.05, 0.1}[s - 1]);
    CHECK(fit.used == 4);
    CHECK(std::abs(fit.slope - 2 * s) <= 0.25);
  }
}

// The same pendulum as pendulum-chain on S2, Galerkin in the sphere's natural chart at q0: no
// multipliers, the unconstrained order min(2s, the rule's) whatever the control times (its errors are
// smaller than the rod's: s = 3 starts at h = 0.2, so that the last of four points stays above round-off).
TEST_CASE("the spherical pendulum on S2 in the natural chart: Galerkin s = 1, 2, 3 with s + 1 Lobatto points has orders 2, 4, 6") {
  for (int s = 1; s <= 3; ++s) {
    CAPTURE(s);
    json method = galerkin_lobatto(s);
    method["chart"] = "natural";
    const OrderFit fit = spherical_pendulum_order(method, std::array<double, 3>{0.02, 0.05, 0.2}[s - 1], nullptr,
                                                  "spherical-pendulum-s2.json");
    CHECK(fit.used == 4);
    CHECK(std::abs(fit.slope - 2 * s) <= 0.25);
  }
}

// The one-step methods with constraints: the index-1 equations, each step projected onto the rod
// and its hidden constraint, keep the method's order (HLW sec. IV.4); implicit methods take the
// field's Jacobian, exact for the rod's quadratic g.
TEST_CASE("the spherical pendulum on a rod: projected explicit midpoint, rk4, implicit midpoint and 2-stage Gauss have orders 2, 4, 2, 4") {
  const std::pair<json, int> methods[] = {{{{"type", "explicit-midpoint"}}, 2},
                                          {{{"type", "rk4"}}, 4},
                                          {{{"type", "implicit-midpoint"}}, 2},
                                          {{{"type", "gauss-collocation"}, {"stages", 2}}, 4}};
  for (const auto& [one_step, order] : methods) {
    CAPTURE(one_step.dump());
    const OrderFit fit = spherical_pendulum_order({{"construction", "one-step"}, {"one_step", one_step}}, 0.02);
    CHECK(fit.used == 4);
    CHECK(std::abs(fit.slope - order) <= 0.25);
  }
}

json constrained_shooting(const char* method, const char* rule) {
  return {{"construction", "shooting"}, {"one_step", {{"type", method}}}, {"quadrature", {{"type", rule}}}};
}

// Shooting with constraints: the shot is the projected one-step map, L_d a function on the sphere's
// Q x Q; the paper's theorem there gives order min(p, q).
TEST_CASE("the spherical pendulum on a rod: shooting with projected explicit midpoint + trapezoid, rk4 + simpson, implicit midpoint + trapezoid and 2-stage Gauss + 3 Lobatto points has orders 2, 4, 2, 4") {
  json gauss = constrained_shooting("gauss-collocation", "gauss-lobatto");
  gauss["one_step"]["stages"] = 2;
  gauss["quadrature"]["points"] = 3;
  const std::pair<json, int> methods[] = {{constrained_shooting("explicit-midpoint", "trapezoid"), 2},
                                          {constrained_shooting("rk4", "simpson"), 4},
                                          {constrained_shooting("implicit-midpoint", "trapezoid"), 2},
                                          {gauss, 4}};
  for (const auto& [method, order] : methods) {
    CAPTURE(method.dump());
    const OrderFit fit = spherical_pendulum_order(method, 0.02);
    CHECK(fit.used == 4);
    CHECK(std::abs(fit.slope - order) <= 0.25);
  }
}

// 10^5 steps of h = 0.01, s = 2: the constraint within 1e-12 and the hidden constraint within 1e-11
// (the bounds), the energy E = |p|^2 / 2 + g x3 bounded: its largest error over the second
// half of the run no more than twice that over the first (a drift would double it).
TEST_CASE("the spherical pendulum on a rod over 1e5 steps: constraint and hidden constraint at round-off, energy bounded") {
  Registry registry{Registry::search_path({})};
  Scene scene;
  constexpr long kSteps = 100000;
  Assembly a = assembled(spherical_pendulum(2, 0.01, kSteps), registry, scene);
  Trajectory trajectory(*a.map, a.q0, a.p0, a.t0, scene.step);
  const auto energy = [](const Eigen::VectorXd& q, const Eigen::VectorXd& p) { return 0.5 * p.squaredNorm() + kGravity * q[2]; };
  const double E0 = energy(a.q0, a.p0);
  double g = 0.0, Gv = 0.0, first = 0.0, second = 0.0;
  for (long k = 1; k <= kSteps; ++k) {
    trajectory.step();
    const Eigen::VectorXd& q = trajectory.q();
    const Eigen::VectorXd& p = trajectory.p();  // m = 1: v = p
    g = std::max(g, a.holonomic->residual(q.data()));
    Gv = std::max(Gv, a.holonomic->velocity_residual(q.data(), p.data()));
    double& half = k <= kSteps / 2 ? first : second;
    half = std::max(half, std::abs(energy(q, p) - E0));
  }
  MESSAGE("constraint ", g, ", hidden constraint ", Gv, ", energy error ", first, " then ", second);
  CHECK(g <= 1e-12);
  CHECK(Gv <= 1e-11);
  CHECK(second <= 2 * first);
  CHECK(first <= 1e-8);
}

namespace {

using State12 = std::vector<double>;  // 12 numbers (a std::array of 12 trips GCC's -Wmaybe-uninitialized in odeint)

// The double spherical pendulum's (x1, x2, x1', x2') at time T, to about 1e-13: M x'' = F - G^T lambda
// with g1 = |x1|^2 / 2, g2 = |x2 - x1|^2 / 2 and (G M^-1 G^T) lambda = G M^-1 F + (G' x'), the
// multipliers in closed form (a 2 x 2 solve).
State12 double_pendulum_reference(const State12& start, double m1, double m2, double T) {
  const auto field = [m1, m2](const State12& y, State12& dy, double) {
    Eigen::Vector3d x1(y[0], y[1], y[2]), x2(y[3], y[4], y[5]), v1(y[6], y[7], y[8]), v2(y[9], y[10], y[11]);
    const Eigen::Vector3d d = x2 - x1, w = v2 - v1, g(0, 0, -kGravity);
    Eigen::Matrix2d S;  // G M^-1 G^T, G = [x1^T 0; -d^T d^T]
    S << x1.squaredNorm() / m1, -x1.dot(d) / m1, -x1.dot(d) / m1, d.squaredNorm() * (1 / m1 + 1 / m2);
    // G M^-1 F = (x1 . g, d . g - d . g) = (x1 . g, 0), G' x' = (|v1|^2, |w|^2)
    const Eigen::Vector2d lambda = S.partialPivLu().solve(Eigen::Vector2d(x1.dot(g) + v1.squaredNorm(), w.squaredNorm()));
    const Eigen::Vector3d a1 = g - (lambda[0] * x1 - lambda[1] * d) / m1, a2 = g - lambda[1] * d / m2;
    for (int k = 0; k < 3; ++k) dy[k] = v1[k], dy[3 + k] = v2[k], dy[6 + k] = a1[k], dy[9 + k] = a2[k];
  };
  return integrated(start, field, T);
}

}  // namespace

// The bound: the composite + rod form at h = 0.01, s = 2 agrees with a reference to 1e-7 at T = 3.
TEST_CASE("the double spherical pendulum on two rods agrees with an independent reference to 1e-7 at T = 3") {
  Registry registry{Registry::search_path({})};
  Scene scene;
  Assembly a = assembled(json::parse(test::read_file(test::kSourceDir / "scenes/multibody/double-spherical-pendulum-rod.json")),
                         registry, scene);
  State12 start(12);
  for (int k = 0; k < 6; ++k) start[k] = a.q0[k], start[6 + k] = a.v0[k];
  const State12 truth = double_pendulum_reference(start, 1.0, 0.5, 3.0);
  Trajectory trajectory(*a.map, a.q0, a.p0, a.t0, scene.step);
  trajectory.advance(scene.steps);
  double error = 0.0;
  for (int k = 0; k < 6; ++k) error = std::max(error, std::abs(trajectory.q()[k] - truth[k]));
  MESSAGE("double spherical pendulum, h = 0.01, s = 2, T = 3: max |x - x_ref| = ", error);
  CHECK(error <= 1e-7);
}

namespace {

json scene_file(const char* name) { return json::parse(test::read_file(test::kSourceDir / "scenes/multibody" / name)); }

// The run record of `document`, run as `varia run` runs it (quiet, nothing written).
json record_of(const json& document, Registry& registry) {
  Scene scene;
  Assembly a = assembled(document, registry, scene);
  RunOptions options;
  options.quiet = true;
  json record;
  options.record = &record;
  run_scene(scene, a, registry, options);
  return record;
}

// pendulum-chain's positions x_i = l_1 q_1 + ... + l_i q_i, from the rods' directions q_i.
Eigen::VectorXd chain_positions(const Eigen::VectorXd& q, const std::vector<double>& lengths) {
  Eigen::VectorXd x(q.size());
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < lengths.size(); ++i) x.segment<3>(3 * i) = sum += lengths[i] * q.segment<3>(3 * i);
  return x;
}

}  // namespace

// Spec "S2 and products": pendulum-chain on S2 x S2 is the same motion as the composite + rods.
TEST_CASE("pendulum-chain on S2 x S2 agrees with the double spherical pendulum's reference to 1e-7 at T = 3 (in the embedding and in the natural chart)") {
  for (const char* name : {"double-spherical-pendulum-s2.json", "double-spherical-pendulum-s2-natural-chart.json"}) {
  CAPTURE(name);
  Registry registry{Registry::search_path({})};
  Scene scene;
  Assembly a = assembled(scene_file(name), registry, scene);
  const std::vector<double> lengths{1.0, 0.7};
  const Eigen::VectorXd x0 = chain_positions(a.q0, lengths), v0 = chain_positions(a.v0, lengths);
  State12 start(12);
  for (int k = 0; k < 6; ++k) start[k] = x0[k], start[6 + k] = v0[k];
  const State12 truth = double_pendulum_reference(start, 1.0, 0.5, 3.0);
  Trajectory trajectory(*a.map, a.q0, a.p0, a.t0, scene.step);
  trajectory.advance(scene.steps);
  const Eigen::VectorXd x = chain_positions(trajectory.q(), lengths);
  double error = 0.0;
  for (int k = 0; k < 6; ++k) error = std::max(error, std::abs(x[k] - truth[k]));
  MESSAGE(std::string(name), ", h = 0.01, s = 2, T = 3: max |x - x_ref| = ", error);
  CHECK(error <= 1e-7);
  }
}

// One rod of length 1 and mass 1: S2's equation (|q|^2 - 1)/2 is the rod's, and the Lagrangians are
// equal, so the two forms take the same steps up to round-off, under Galerkin (the scenes' own
// method) and under shooting with constraints.
TEST_CASE("pendulum-chain on S2 takes the steps of the particle on a rod, under Galerkin and shooting") {
  Registry registry{Registry::search_path({})};
  json sphere_document = scene_file("spherical-pendulum-s2.json"), rod_document = scene_file("spherical-pendulum-rod-s2.json");
  for (const json& method : {sphere_document["method"], constrained_shooting("rk4", "simpson")}) {
    CAPTURE(method.dump());
    sphere_document["method"] = rod_document["method"] = method;
    Scene sphere_scene, rod_scene;
    Assembly sphere = assembled(sphere_document, registry, sphere_scene);
    Assembly rod = assembled(rod_document, registry, rod_scene);
    Trajectory on_sphere(*sphere.map, sphere.q0, sphere.p0, sphere.t0, sphere_scene.step);
    Trajectory on_rod(*rod.map, rod.q0, rod.p0, rod.t0, rod_scene.step);
    on_sphere.advance(1000);
    on_rod.advance(1000);
    const double difference = (on_sphere.q() - on_rod.q()).lpNorm<Eigen::Infinity>();
    MESSAGE("S2 against the rod after 1000 steps: ", difference);
    CHECK(difference <= 1e-12);
  }
}

namespace {

// The run record of `steps` steps of a pendulum-chain scene observing its momentum, its constraint
// and its energy, with the momentum error relative to the vertical angular momentum J0 as
// "momentum_relative".
json momentum_record(const char* name, long steps) {
  Registry registry{Registry::search_path({})};
  Scene scene;
  json document = scene_file(name);
  document.erase("t_end");
  document["steps"] = steps;
  document["observe"] = {"momentum", "constraint", "energy"};
  json record = record_of(document, registry);
  const Assembly a = assembled(document, registry, scene);
  double J0 = 0.0;
  a.lagrangian->momentum(a.q0.data(), a.v0.data(), &J0);
  record["momentum_relative"] = record["momentum_error_max"].get<double>() / std::abs(J0);
  MESSAGE(std::string(name), ": vertical momentum ", J0, ", relative error over ", steps, " steps ", record["momentum_relative"].get<double>(),
          ", constraint ", record["constraint_error_max"].get<double>(), ", energy ", record["energy_error_max"].get<double>());
  return record;
}

}  // namespace

// Noether with the manifold's own constraint: |q_i| = 1 is invariant under rotations about e3.
TEST_CASE("pendulum-chain on S2 x S2 keeps its vertical angular momentum to 1e-13 over 1e5 steps") {
  const json record = momentum_record("double-spherical-pendulum-s2.json", 100000);
  CHECK(record["momentum_relative"].get<double>() <= 1e-13);
  CHECK(record["constraint_error_max"].get<double>() <= 1e-12);
}

// Noether in the natural chart: the chart is SO(3)-equivariant, so rotations about e3 leave L_d
// invariant; the points stay on the spheres without multipliers.
TEST_CASE("pendulum-chain on S2 x S2 in the natural chart keeps its vertical angular momentum to 1e-13 over 2e4 steps") {
  const json record = momentum_record("double-spherical-pendulum-s2-natural-chart.json", 20000);
  CHECK(record["momentum_relative"].get<double>() <= 1e-13);
  CHECK(record["constraint_error_max"].get<double>() <= 1e-13);
  CHECK(record["energy_error_max"].get<double>() <= 1e-6);
}

// Spec: initial.p on S2 is dL/dq' in the ambient form with q . p = 0, and so is every written p.
TEST_CASE("on S2 x S2 a momentum is read and written orthogonal to the normals, and restarts the same motion") {
  Registry registry{Registry::search_path({})};
  Scene scene;
  json document = scene_file("double-spherical-pendulum-s2.json");
  document["t_end"] = 0.5;
  const json record = record_of(document, registry);
  const auto q = record["final"]["q"].get<std::vector<double>>(), p = record["final"]["p"].get<std::vector<double>>();
  for (int i = 0; i < 2; ++i) {
    const double along = q[3 * i] * p[3 * i] + q[3 * i + 1] * p[3 * i + 1] + q[3 * i + 2] * p[3 * i + 2];
    CHECK(std::abs(along) <= 1e-14);
  }
  json restart = scene_file("double-spherical-pendulum-s2.json");
  restart["initial"] = {{"q", q}, {"p", p}};
  restart["t_end"] = 0.5;
  const json record_again = record_of(restart, registry);
  json onward = scene_file("double-spherical-pendulum-s2.json");
  onward["t_end"] = 1.0;
  const json record_whole = record_of(onward, registry);
  const auto q1 = record_again["final"]["q"].get<std::vector<double>>(), q2 = record_whole["final"]["q"].get<std::vector<double>>();
  for (int k = 0; k < 6; ++k) CHECK(std::abs(q1[k] - q2[k]) <= 1e-12);
  json across = scene_file("double-spherical-pendulum-s2.json");
  across["initial"] = {{"q", q}, {"p", {p[0] + 0.1 * q[0], p[1] + 0.1 * q[1], p[2] + 0.1 * q[2], p[3], p[4], p[5]}}};
  CHECK_THROWS_WITH_AS(assembled(across, registry, scene), doctest::Contains("/initial/p"), InputError);
}

// Four particles on a chain of rods: n = 12 - 4 = 8 dimensions, 16 jet variables, more than a jet
// holds, so the shot's sensitivities come in passes (docs/shooting.md). Against Galerkin degree 4
// at h/4 (order 8) as the reference.
TEST_CASE("shooting with constraints in passes: a chain of four rods under rk4 + simpson agrees with a galerkin reference") {
  Registry registry{Registry::search_path({})};
  json document = json::parse(test::read_file(test::kSourceDir / "scenes/multibody/double-spherical-pendulum-rod.json"));
  const int particles = 4;
  document["system"]["manifold"]["dim"] = 3 * particles;
  document["system"]["lagrangian"]["masses"] = std::vector<double>(particles, 1.0);
  json rods = json::array({{{"type", "rod"}, {"anchor", {0, 0, 0}}, {"particle", 0}, {"length", 1}}});
  for (int i = 0; i + 1 < particles; ++i) rods.push_back({{"type", "rod"}, {"between", {i, i + 1}}, {"length", 1}});
  document["system"]["constraints"] = rods;
  std::vector<double> q, v;
  for (int i = 1; i <= particles; ++i) {
    q.insert(q.end(), {i * std::sin(0.6), 0.0, -i * std::cos(0.6)});
    v.insert(v.end(), {0.0, 0.5 * i, 0.0});
  }
  document["initial"] = {{"q", q}, {"v", v}};
  document.erase("t_end");
  const auto final_q = [&](const json& method, double h, long steps) {
    json d = document;
    d["method"] = method;
    d["step"] = h;
    d["steps"] = steps;
    return record_of(d, registry)["final"]["q"].get<std::vector<double>>();
  };
  const std::vector<double> shot = final_q(constrained_shooting("rk4", "simpson"), 0.01, 100);
  json reference_method = galerkin_lobatto(4);
  const std::vector<double> reference = final_q(reference_method, 0.0025, 400);
  double error = 0.0;
  for (std::size_t k = 0; k < shot.size(); ++k) error = std::max(error, std::abs(shot[k] - reference[k]));
  MESSAGE("chain of four rods, shooting rk4 + simpson at h = 0.01, T = 1: max |q - q_ref| = ", error);
  CHECK(error <= 1e-7);
}

TEST_CASE("S2 is refused where it cannot be served, the natural chart off S2 and above its jets' size, and a point off the sphere at /initial/q") {
  Registry registry{Registry::search_path({})};
  Scene scene;
  json hamiltonian = scene_file("spherical-pendulum-s2.json");
  hamiltonian["method"] = constrained_shooting("rk4", "simpson");
  hamiltonian["method"]["form"] = "hamiltonian";
  CHECK_THROWS_WITH_AS(assembled(hamiltonian, registry, scene),
                       doctest::Contains("/system/manifold: with constraints"), InputError);
  json off = scene_file("spherical-pendulum-s2.json");
  off["initial"]["q"] = {0.85, 0, -0.54};
  CHECK_THROWS_WITH_AS(assembled(off, registry, scene), doctest::Contains("/initial/q"), InputError);
  json natural_on_rod = json::parse(test::read_file(test::kSourceDir / "scenes/multibody/spherical-pendulum-rod-s2.json"));
  natural_on_rod["method"]["chart"] = "natural";
  CHECK_THROWS_WITH_AS(assembled(natural_on_rod, registry, scene), doctest::Contains("/method/chart"), InputError);
  json too_many = scene_file("double-spherical-pendulum-s2-natural-chart.json");
  too_many["method"]["degree"] = 4;
  too_many["method"]["quadrature"]["points"] = 5;
  CHECK_THROWS_WITH_AS(assembled(too_many, registry, scene), doctest::Contains("/method/degree"), InputError);
  json mixed = scene_file("spherical-pendulum-s2.json");
  mixed["system"]["manifold"] = {{"type", "product"}, {"factors", {{{"type", "S2"}}, {{"type", "SO3"}}}}};
  CHECK_THROWS_WITH_AS(assembled(mixed, registry, scene), doctest::Contains("/system/manifold"), InputError);
}

TEST_CASE("constraints are refused where they cannot be served, and a start off them is refused at its pointer") {
  Registry registry{Registry::search_path({})};
  Scene scene;
  json hamiltonian = spherical_pendulum(1, 0.01, 10);
  hamiltonian["method"] = constrained_shooting("rk4", "simpson");
  hamiltonian["method"]["form"] = "hamiltonian";
  CHECK_THROWS_WITH_AS(assembled(hamiltonian, registry, scene),
                       doctest::Contains("/system/constraints: with constraints"), InputError);
  json off = spherical_pendulum(1, 0.01, 10);
  off["initial"]["q"] = {0.85, 0, -0.54};
  CHECK_THROWS_WITH_AS(assembled(off, registry, scene), doctest::Contains("/initial/q"), InputError);
  json across = spherical_pendulum(1, 0.01, 10);
  across["initial"]["v"] = {0.1, 2.5, 0};
  CHECK_THROWS_WITH_AS(assembled(across, registry, scene), doctest::Contains("/initial/v"), InputError);
  json stray = spherical_pendulum(1, 0.01, 10);
  stray["system"]["constraints"][0] = {{"type", "rod"}, {"between", {0, 1}}};
  CHECK_THROWS_WITH_AS(assembled(stray, registry, scene), doctest::Contains("/system/constraints/0"), InputError);
}

}  // namespace varia::host

namespace varia::host {
namespace {

// The constrained map followed by p1 -> (1 - 1e-2) p1: still on the constraint's cotangent space
// (G M^-1 p = 0 is linear in p), but it contracts the phase-space volume: not symplectic there.
class DampedMap final : public DiscreteHamiltonianMap {
 public:
  explicit DampedMap(DiscreteHamiltonianMap& map) : map_(map) {}
  int point_size() const override { return map_.point_size(); }
  int dim() const override { return map_.dim(); }
  const SolverStatistics& solver_statistics() const override { return map_.solver_statistics(); }
  const EvaluationCounters& evaluations() const override { return map_.evaluations(); }

 protected:
  void take_step(const double* q0, const double* p0, double t0, double h, double* q1, double* p1) override {
    map_.step(q0, p0, t0, h, q1, p1);
    for (int k = 0; k < dim(); ++k) p1[k] *= 1.0 - 1e-2;
  }

 private:
  DiscreteHamiltonianMap& map_;
};

}  // namespace

TEST_CASE("symplecticity on the constraint's cotangent bundle: holds for the constrained Galerkin and shooting maps, not for a damped one") {
  Registry registry{Registry::search_path({})};
  for (const json& method : {galerkin_lobatto(2), constrained_shooting("rk4", "simpson")}) {
    CAPTURE(method.dump());
    Scene scene;
    Assembly a = assembled(spherical_pendulum(method, 0.01, 10), registry, scene);
    const Eigen::MatrixXd M = Eigen::MatrixXd::Identity(3, 3);
    const Eigen::MatrixXd tangent = constrained_tangent_basis(*a.holonomic, M, a.q0.data(), a.p0.data(), 1e-3, 2.5e-3);
    REQUIRE(tangent.cols() == 4);
    const Eigen::VectorXd steps = Eigen::VectorXd::Constant(6, 1e-3);
    const auto held = symplecticity_defect(*a.map, *a.manifold, a.q0.data(), a.p0.data(), 0.05, steps, tangent);
    MESSAGE("symplecticity defect on the bundle: ", held.defect);
    CHECK(held.defect <= 1e-9);
    DampedMap damped(*a.map);
    const auto broken = symplecticity_defect(damped, *a.manifold, a.q0.data(), a.p0.data(), 0.05, steps, tangent);
    CHECK(broken.defect >= 1e-3);
    // On the whole of T*R^3 the constrained map is not symplectic (it maps onto the bundle): the
    // unrestricted measurement would call a correct integrator wrong, which is why verify restricts it.
    const auto whole = symplecticity_defect(*a.map, *a.manifold, a.q0.data(), a.p0.data(), 0.05, steps);
    CHECK(whole.defect >= 1e-3);
  }
}

namespace {

// `varia verify scenes/multibody/<name>` exits 0 (every predicted property measured to hold), and
// its table has each of `rows` (the start of a property's row).
void check_verified(const std::string& name, std::initializer_list<const char*> rows) {
  const auto outcome = test::run_varia("verify scenes/multibody/" + name);
  CAPTURE(outcome.out);
  CAPTURE(outcome.err);
  CHECK(outcome.code == 0);
  for (const char* row : rows) CHECK(test::contains(outcome.out, row));
}

}  // namespace

TEST_CASE("varia verify holds every predicted property of the constrained spherical pendulum, s = 1, 2, 3") {
  for (int s = 1; s <= 3; ++s) check_verified("spherical-pendulum-rod-s" + std::to_string(s) + ".json", {"global_order"});
}

TEST_CASE("varia verify holds every predicted property of shooting with constraints: a rod, and S2 x S2 with its momentum") {
  for (const char* name : {"spherical-pendulum-rod-shooting.json", "double-spherical-pendulum-s2-shooting.json"})
    check_verified(name, {"global_order"});
}

TEST_CASE("varia verify holds every predicted property of galerkin in the natural chart of S2 and of S2 x S2") {
  for (const char* name : {"spherical-pendulum-s2-natural-chart.json", "double-spherical-pendulum-s2-natural-chart.json"})
    check_verified(name, {"g_invariant               true", "momentum_conserved        true"});
}

}  // namespace varia::host

namespace varia::host {

// In TEST_SUITE("long"), names without commas (doctest_discover_tests).
TEST_SUITE("long") {
  TEST_CASE("varia verify holds every predicted property of the 100-link rod chain") {
    const auto outcome = test::run_varia("verify scenes/multibody/rod-chain-100.json");
    CAPTURE(outcome.out);
    CAPTURE(outcome.err);
    CHECK(outcome.code == 0);
    CHECK(test::contains(outcome.out, "symplectic"));
  }
}

// A constraint that is not quadratic: tests/fault_plugins/quartic_anchor.cpp writes the rod from the
// origin as (|x|^4 - 1) / 4, the same zero set and normals. Galerkin (its Newton Jacobian takes the
// weighted Hessian at every point) moves the pendulum as on the rod; the one-step methods integrate
// its own index-1 field, which differs from the rod's off the sphere, where the stages are: another
// method of the same order on the same motion, measured against the reference. Implicit midpoint's
// stage Newton takes the field's Jacobian with the constraint's curvature derivative
// (Constraint::curvature_derivative); without it (the plugin's parameter false) the implicit method is
// refused at /system/constraints (spec), and shooting, which needs quadratic constraints, always is.
TEST_CASE("a constraint that is not quadratic moves the pendulum as the rod with the same zero set does under galerkin, "
          "rk4 and implicit midpoint, and implicit one-step methods without its curvature derivative and shooting "
          "refuse it at /system/constraints") {
  Registry registry{Registry::search_path({VARIA_FAULT_PLUGIN_DIR})};
  const auto final_q = [&](const json& method, bool quartic) {
    json document = spherical_pendulum(method, 0.01, 100);
    if (quartic) document["system"]["constraints"] = json::array({{{"type", "quartic-anchor"}}});
    Scene scene;
    Assembly a = assembled(document, registry, scene);
    Trajectory trajectory(*a.map, a.q0, a.p0, a.t0, scene.step);
    trajectory.advance(scene.steps);
    return Eigen::VectorXd(trajectory.q());
  };
  // Galerkin holds g = 0 at the control points and the multiplier's term along the same normal: the
  // same discrete motion, to round-off.
  const double apart = (final_q(galerkin_lobatto(2), true) - final_q(galerkin_lobatto(2), false)).cwiseAbs().maxCoeff();
  MESSAGE("galerkin degree 2: the quartic constraint and the rod 100 steps apart by ", apart);
  CHECK(apart < 1e-13);
  const json quartic = json::array({{{"type", "quartic-anchor"}}});
  for (const auto& [type, order] : {std::pair{"rk4", 4}, std::pair{"implicit-midpoint", 2}}) {
    const OrderFit fit = spherical_pendulum_order({{"construction", "one-step"}, {"one_step", {{"type", type}}}}, 0.02, quartic);
    CHECK(fit.used == 4);
    CHECK(std::abs(fit.slope - order) <= 0.25);
  }
  const std::pair<json, const char*> refused[] = {
      {{{"construction", "one-step"}, {"one_step", {{"type", "implicit-midpoint"}}}},
       "/system/constraints: with constraints that do not give the derivative of v^T H_i(q) v in q"},
      {constrained_shooting("rk4", "simpson"),
       "/system/constraints: with constraints the shooting construction takes quadratic constraints only"}};
  for (const auto& [method, message] : refused) {
    json document = spherical_pendulum(method, 0.01, 10);
    document["system"]["constraints"] = json::array({{{"type", "quartic-anchor"}, {"curvature_derivative", false}}});
    Scene scene;
    CHECK_THROWS_WITH_AS(assembled(document, registry, scene), doctest::Contains(message), InputError);
  }
}

}  // namespace varia::host
