// Newton's mutual attraction of every pair of particles (spec: "Composed systems: effects"),
// softened by eps:
//
//   V = -G sum_{i<j} m_i m_j / r_ij,   r_ij = sqrt(|x_i - x_j|^2 + eps^2).
//
// With d = x_i - x_j and k = G m_i m_j: dV/dx_i = k d / r^3 = -dV/dx_j, and the d x d block
// B = k (I / r^3 - 3 d d^T / r^5) (the Hessian of -k / r in d) enters the Hessian at (i, i) and
// (j, j), and -B at (i, j) and (j, i). Every particle interacts with every other, so the Hessian
// is dense over all N d coordinates and an evaluation costs N (N - 1) / 2 pairs: the outer solar
// system (HLW sec. I.2.3, scenes/effects/outer-solar-system.json) is its model use. With eps = 0,
// two particles at one point are a fault (V is singular there).
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "varia/sdk/particle_effect.hpp"

namespace {

class Gravitation final : public varia::sdk::TemplatedEffect<Gravitation> {
 public:
  static constexpr const char* version = "1.0.0";
  static constexpr const char* parameter_schema = R"json({
    "$schema": "http://json-schema.org/draft-07/schema#",
    "type": "object",
    "properties": {
      "G": {"type": "number", "exclusiveMinimum": 0, "default": 1,
            "description": "the gravitational constant G in V = -G sum_{i<j} m_i m_j / sqrt(|x_i - x_j|^2 + eps^2)"},
      "softening": {"type": "number", "minimum": 0, "default": 0,
                    "description": "eps, the softening length (0: Newton's law exactly)"}
    },
    "examples": [{}, {"G": 2.95912208286e-4}, {"G": 0.5, "softening": 0.1}],
    "additionalProperties": false
  })json";
  static constexpr const char* properties = R"json({
    "potential": "-G sum_{i<j} m_i m_j / sqrt(|x_i - x_j|^2 + eps^2)",
    "coordinates": "all"
  })json";

  Gravitation(const nlohmann::json& parameters, const varia::sdk::Context&)
      : G_(parameters.value("G", 1.0)), softening_(parameters.value("softening", 0.0)) {
    if (!(G_ > 0)) throw std::invalid_argument("parameter 'G' must be a number > 0");
    if (!(softening_ >= 0)) throw std::invalid_argument("parameter 'softening' must be a number >= 0");
  }

 private:
  void attach() override {
    for (int i = 0; i < particles_; ++i) use_particle(i, "particles");
    dense_pattern();
    difference_.resize(d_);
  }

  friend varia::sdk::TemplatedEffect<Gravitation>;
  void second_order(const double* x, double* hessian) const {
    const int n = particles_ * d_;
    std::fill(hessian, hessian + static_cast<std::size_t>(n) * n, 0.0);
    for (int i = 0; i < particles_; ++i)
      for (int j = i + 1; j < particles_; ++j) add_pair_hessian(i, j, x, hessian);
  }

  // V = -sum_{i<j} k_ij / r_ij and dV/dx (k_ij = G m_i m_j, r_ij^2 = |x_i - x_j|^2 + softening^2),
  // at doubles or jets.
  template <class T>
  void first_order(const T* x, T* value, T* gradient) const {
    using std::sqrt;
    if (value != nullptr) *value = T(0.0);
    if (gradient != nullptr) std::fill(gradient, gradient + particles_ * d_, T(0.0));
    for (int i = 0; i < particles_; ++i)
      for (int j = i + 1; j < particles_; ++j) {
        const auto difference = [&](int a) -> T { return x[i * d_ + a] - x[j * d_ + a]; };
        T s(softening_ * softening_);
        for (int a = 0; a < d_; ++a) s += difference(a) * difference(a);
        if (varia::value_of(s) == 0.0) throw std::domain_error("two particles are at one point of an unsoftened gravitation");
        const double k = G_ * masses_[i] * masses_[j];
        const T r = sqrt(s);
        if (value != nullptr) *value -= k / r;
        if (gradient == nullptr) continue;
        const T k_r3 = k / (s * r);
        for (int a = 0; a < d_; ++a) {
          const T g = k_r3 * difference(a);
          gradient[i * d_ + a] += g;
          gradient[j * d_ + a] -= g;
        }
      }
  }

  // The pair (i, j)'s block of the Hessian, added in place (column-major, n x n over all
  // coordinates: dense_pattern's order).
  void add_pair_hessian(int i, int j, const double* x, double* hessian) const {
    const int n = particles_ * d_;
    double* dd = difference_.data();
    double s = softening_ * softening_;
    for (int a = 0; a < d_; ++a) {
      dd[a] = x[i * d_ + a] - x[j * d_ + a];
      s += dd[a] * dd[a];
    }
    const double k = G_ * masses_[i] * masses_[j], r = std::sqrt(s), k_r3 = k / (s * r);
    for (int b = 0; b < d_; ++b)
      for (int a = 0; a < d_; ++a) {
        const double B = k_r3 * ((a == b ? 1.0 : 0.0) - 3.0 * dd[a] * dd[b] / s);
        hessian[static_cast<std::size_t>(i * d_ + b) * n + i * d_ + a] += B;
        hessian[static_cast<std::size_t>(j * d_ + b) * n + j * d_ + a] += B;
        hessian[static_cast<std::size_t>(j * d_ + b) * n + i * d_ + a] -= B;
        hessian[static_cast<std::size_t>(i * d_ + b) * n + j * d_ + a] -= B;
      }
  }

  double G_, softening_;
  mutable std::vector<double> difference_;  // x_i - x_j, sized at bind
};

}  // namespace

VARIA_PLUGIN(Gravitation, effect, gravitation)
