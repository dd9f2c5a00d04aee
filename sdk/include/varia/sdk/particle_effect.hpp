// An effect over particles (abi/include/varia/abi/effect.hpp), for effect plugins: the bound
// system (space_dim d, the particles and their masses), the coordinates of the particles an effect
// names, a dense Hessian pattern over them, and the boundary rule (exceptions become Status
// messages). A plugin derives from ParticleEffect, chooses its particles in attach() and writes
// V, dV/dx and the Hessian in potential(); docs/writing-effects.md is the walk-through, and
// varia-conformance checks the derivatives (sdk/conformance/effect.hpp).
#pragma once

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "varia/abi/effect.hpp"
#include "varia/sdk/plugin.hpp"

namespace varia::sdk {

// A parameter value that names a particle: a non-negative integer (`name`: the parameter's name).
inline int particle_index(const nlohmann::json& value, const char* name) {
  if (!value.is_number_integer() || value.get<long>() < 0)
    throw std::invalid_argument(std::string("parameter '") + name + "' must be a particle index >= 0, got " +
                                value.dump());
  return value.get<int>();
}

// A parameter that is a vector of numbers, or `fallback` when absent.
inline std::vector<double> vector_parameter(const nlohmann::json& parameters, const char* key,
                                            std::vector<double> fallback = {}) {
  if (!parameters.contains(key)) return fallback;
  const auto& value = parameters.at(key);
  if (!value.is_array()) throw std::invalid_argument(std::string("parameter '") + key + "' must be an array of numbers");
  for (const auto& x : value)
    if (!x.is_number()) throw std::invalid_argument(std::string("parameter '") + key + "' must be an array of numbers");
  return value.get<std::vector<double>>();
}

class ParticleEffect : public Effect {
 public:
  Status bind(int space_dim, int particles, const double* masses) noexcept final {
    return guarded(error_, [&] {
      d_ = space_dim;
      particles_ = particles;
      masses_.assign(masses, masses + particles);
      attach();
    });
  }
  int coordinates(const int** indices) const noexcept final {
    *indices = indices_.data();
    return static_cast<int>(indices_.size());
  }
  int hessian_pattern(const int** rows, const int** cols) const noexcept final {
    *rows = rows_.data();
    *cols = cols_.data();
    return static_cast<int>(rows_.size());
  }
  Status evaluate(const double* x, double* value, double* gradient, double* hessian) noexcept final {
    return guarded(error_, [&] { potential(x, value, gradient, hessian); });
  }
  Status gradient_jet(const Jet2* x, Jet2* value, Jet2* gradient) noexcept final {
    return guarded(error_, [&] { potential_jet(x, value, gradient); });
  }

 protected:
  // Chooses the coordinates (use_particle) and the Hessian pattern (dense_pattern) once bound.
  virtual void attach() = 0;
  // V, dV/dx and the Hessian values (in pattern order) at the gathered coordinates.
  virtual void potential(const double* x, double* value, double* gradient, double* hessian) const = 0;
  // V and dV/dx at jets, for the shooting construction: an effect that gives it also returns true
  // from evaluates_at_jets(). TemplatedEffect below does both from V and dV/dx written once.
  virtual void potential_jet(const Jet2* /*x*/, Jet2* /*value*/, Jet2* /*gradient*/) const {
    throw std::logic_error("this effect does not evaluate at jets");
  }

  // Appends particle i's d coordinates; `key` names the parameter that named it.
  void use_particle(int i, const char* key) {
    if (i >= particles_)
      throw std::invalid_argument(std::string(key) + ": particle " + std::to_string(i) + " does not exist (the system has " +
                                  std::to_string(particles_) + ")");
    for (int k = 0; k < d_; ++k) indices_.push_back(i * d_ + k);
  }
  // Every entry of the k x k Hessian, column-major: the values are a dense matrix.
  void dense_pattern() {
    std::vector<int> all(indices_.size());
    for (std::size_t j = 0; j < all.size(); ++j) all[j] = static_cast<int>(j);
    block_pattern(all);
  }
  // Appends the entries (r, c) for every r, c in `coordinates` (positions in the coordinates,
  // not indices into q), column-major: a dense block over them. Blocks may overlap (several
  // springs at one particle): the composite adds the values of a repeated entry.
  void block_pattern(const std::vector<int>& coordinates) {
    for (int c : coordinates)
      for (int r : coordinates) {
        rows_.push_back(r);
        cols_.push_back(c);
      }
  }
  // A parameter vector of the space's dimension d.
  void check_space_vector(const std::vector<double>& x, const char* key) const {
    if (static_cast<int>(x.size()) != d_)
      throw std::invalid_argument(std::string("parameter '") + key + "' must have space_dim = " + std::to_string(d_) +
                                  " numbers, got " + std::to_string(x.size()));
  }

  int d_ = 0, particles_ = 0;
  std::vector<double> masses_;

 private:
  std::vector<int> indices_, rows_, cols_;
  std::string error_;
};

// An effect whose V and dV/dx are written once as a template on the scalar (double or Jet2), so
// that it serves the shooting construction as well: Derived implements
//   template <class T> void first_order(const T* x, T* value, T* gradient) const;
//   void second_order(const double* x, double* hessian) const;  // Hessian values, pattern order
// (value or gradient may be null) and declares `friend varia::sdk::TemplatedEffect<Derived>;`.
template <class Derived>
class TemplatedEffect : public ParticleEffect {
 public:
  bool evaluates_at_jets() const noexcept final { return true; }

 protected:
  void potential(const double* x, double* value, double* gradient, double* hessian) const final {
    derived().first_order(x, value, gradient);
    if (hessian != nullptr) derived().second_order(x, hessian);
  }
  void potential_jet(const Jet2* x, Jet2* value, Jet2* gradient) const final {
    derived().first_order(x, value, gradient);
  }

 private:
  const Derived& derived() const { return static_cast<const Derived&>(*this); }
};

}  // namespace varia::sdk
