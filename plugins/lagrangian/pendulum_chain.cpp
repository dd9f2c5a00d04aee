// N point masses on massless rods hanging from a fixed pivot at the origin, in gravity g along -e3
// (spec: "Constrained systems, S2 and products"), on the product of N S2: the position is the rods'
// unit directions q_1..q_N (3 numbers each, in the embedding), the velocity their derivatives
// q_i'. Mass i sits at x_i = l_1 q_1 + ... + l_i q_i, so that
//   L = sum_i 1/2 m_i |x_i'|^2 - m_i g e3 . x_i.
// Its mass matrix in (q_1', ..., q_N') is constant, M_jk = l_j l_k (m_max(j,k) + ... + m_N) I_3:
// the constructions serve S2 in its embedding with the multipliers of |q_i| = 1
// (Manifold::defining_constraint), and the same motion is the `composite` of N particles with
// `gravity` and `rod`s. L is invariant under rotations about the vertical, q_i -> Q q_i for all i
// (and |q_i| = 1 with it); its Noether momentum is the angular momentum about e3,
// e3 . sum_i m_i x_i x x_i'.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "rigid_body.hpp"
#include "support.hpp"

namespace {

using varia::sdk::Vec;

std::vector<double> positive_list(const nlohmann::json& parameters, const char* key) {
  std::vector<double> values;
  for (const auto& value : parameters.value(key, nlohmann::json::array({1.0}))) {
    if (!value.is_number() || !(value.get<double>() > 0))
      throw std::invalid_argument(std::string("parameter '") + key + "' must list numbers > 0, got " + value.dump());
    values.push_back(value.get<double>());
  }
  return values;
}

std::string product_of_s2(std::size_t n) {
  if (n == 1) return "S2";
  std::string name = "product(";
  for (std::size_t i = 0; i < n; ++i) name += i > 0 ? ",S2" : "S2";
  return name + ")";
}

// 3 N, after checking that the lists agree and that the manifold has one S2 per mass.
int dimension(const nlohmann::json& parameters, const varia::sdk::Context& context) {
  const std::size_t n = positive_list(parameters, "masses").size();
  if (positive_list(parameters, "lengths").size() != n)
    throw std::invalid_argument("lengths: expected one length per mass (" + std::to_string(n) + ")");
  if (context.manifold != product_of_s2(n) && !(n == 1 && context.manifold == "product(S2)"))
    throw std::invalid_argument("pendulum-chain: " + std::to_string(n) + " masses need the manifold " +
                                product_of_s2(n) + " (one S2 per rod), got " + context.manifold);
  return static_cast<int>(3 * n);
}

class PendulumChain final : public varia::sdk::AutodiffLagrangian<PendulumChain> {
 public:
  static constexpr const char* version = "1.0.0";
  static constexpr const char* parameter_schema = R"json({
    "$schema": "http://json-schema.org/draft-07/schema#",
    "type": "object",
    "properties": {
      "masses": {"type": "array", "minItems": 1, "items": {"type": "number", "exclusiveMinimum": 0},
                 "default": [1], "description": "m_1..m_N, from the pivot down"},
      "lengths": {"type": "array", "minItems": 1, "items": {"type": "number", "exclusiveMinimum": 0},
                  "default": [1], "description": "l_1..l_N, rod i from mass i - 1 (the pivot for i = 1) to mass i"},
      "gravity": {"type": "number", "minimum": 0, "default": 1,
                  "description": "g, the gravitational acceleration, along -e3"}
    },
    "additionalProperties": false
  })json";
  static constexpr const char* properties = R"json({
    "lagrangian": "sum_i 1/2 m_i |x_i'|^2 - m_i g e3 . x_i, x_i = l_1 q_1 + ... + l_i q_i",
    "energy": "sum_i 1/2 m_i |x_i'|^2 + m_i g e3 . x_i",
    "manifold": "product of N S2, one per rod (S2 for N = 1)",
    "symmetry": "SO(2), rotations about the vertical e3 (q_i -> Q q_i)",
    "momentum_map": "e3 . sum_i m_i x_i x x_i'",
    "exact_solution": false
  })json";

  PendulumChain(const nlohmann::json& parameters, const varia::sdk::Context& context)
      : AutodiffLagrangian(dimension(parameters, context), dimension(parameters, context)),
        masses_(positive_list(parameters, "masses")),
        lengths_(positive_list(parameters, "lengths")),
        gravity_(parameters.value("gravity", 1.0)) {}

  template <class T>
  T lagrangian(const Vec<T>& q, const Vec<T>& v) const {
    T L = T(0.0);
    T x[3] = {T(0.0), T(0.0), T(0.0)}, dx[3] = {T(0.0), T(0.0), T(0.0)};
    for (std::size_t i = 0; i < masses_.size(); ++i) {
      for (int k = 0; k < 3; ++k) {
        x[k] += lengths_[i] * q(3 * i + k);
        dx[k] += lengths_[i] * v(3 * i + k);
      }
      L += (0.5 * masses_[i]) * (dx[0] * dx[0] + dx[1] * dx[1] + dx[2] * dx[2]) - (masses_[i] * gravity_) * x[2];
    }
    return L;
  }

  const char* symmetry_group() const noexcept override { return "SO(2)"; }
  int momentum_size() const noexcept override { return 1; }
  varia::Status momentum(const double* q, const double* v, double* J) noexcept override {
    return varia::sdk::guarded(error_, [&] {
      Eigen::Vector3d x = Eigen::Vector3d::Zero(), dx = Eigen::Vector3d::Zero();
      double sum = 0.0;
      for (std::size_t i = 0; i < masses_.size(); ++i) {
        x += lengths_[i] * Eigen::Vector3d(q[3 * i], q[3 * i + 1], q[3 * i + 2]);
        dx += lengths_[i] * Eigen::Vector3d(v[3 * i], v[3 * i + 1], v[3 * i + 2]);
        sum += masses_[i] * (x(0) * dx(1) - x(1) * dx(0));  // e3 . (x x dx)
      }
      J[0] = sum;
    });
  }
  // Q q_i and Q q_i' for one rotation Q about e3.
  varia::Status act(unsigned seed, const double* q, const double* v, double* gq, double* gv) noexcept override {
    return varia::sdk::guarded(error_, [&] {
      const Eigen::Vector3d vertical = Eigen::Vector3d::UnitZ();
      const Eigen::Matrix3d Q = varia::plugins::random_rotation(seed, &vertical);
      for (std::size_t i = 0; i < masses_.size(); ++i) {
        Eigen::Map<Eigen::Vector3d>(gq + 3 * i) = Q * Eigen::Map<const Eigen::Vector3d>(q + 3 * i);
        Eigen::Map<Eigen::Vector3d>(gv + 3 * i) = Q * Eigen::Map<const Eigen::Vector3d>(v + 3 * i);
      }
    });
  }

 private:
  std::vector<double> masses_, lengths_;
  double gravity_;
};

}  // namespace

VARIA_PLUGIN(PendulumChain, lagrangian, pendulum_chain)
