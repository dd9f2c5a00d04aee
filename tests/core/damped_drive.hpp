// The damped, driven oscillator x'' + c x' + x = A cos(w t) on R^1 for the constructions with
// forces (Marsden & West 2001, sec. 3.2): the force f = -c v + A cos(w t) with its Jacobian entry,
// and the exact solution from x(0) = x0, x'(0) = 0.
#pragma once

#include <cmath>

#include "varia/abi/force.hpp"

namespace varia::testing {

constexpr double kDamping = 0.1, kAmplitude = 0.5, kFrequency = 1.3;

// f = -c v + A cos(w t) on R^1, with its Jacobian entry df/dv = -c.
struct DampedDrive : Force {
  int position_size() const noexcept override { return 1; }
  int velocity_size() const noexcept override { return 1; }
  int jacobian_pattern(const int** rows, const int** cols) const noexcept override {
    *rows = &zero;
    *cols = &one;
    return 1;
  }
  Status evaluate(double t, const double*, const double* v, double* f, double* jacobian) noexcept override {
    f[0] = -kDamping * v[0] + amplitude * std::cos(kFrequency * t);
    if (jacobian != nullptr) jacobian[0] = -kDamping;
    return nullptr;
  }
  double amplitude = kAmplitude;
  int zero = 0, one = 1;
};

// x'' + c x' + x = A cos(w t), x(0) = x0, x'(0) = 0: the steady state X cos + Y sin plus the
// underdamped transient e^{-gt} (a cos + b sin)(w_d t), g = c/2, w_d = sqrt(1 - g^2).
inline double damped_exact(double t, double x0, double amplitude) {
  const double k = 1.0 - kFrequency * kFrequency, den = k * k + kDamping * kDamping * kFrequency * kFrequency;
  const double X = amplitude * k / den, Y = amplitude * kDamping * kFrequency / den;
  const double g = kDamping / 2, wd = std::sqrt(1.0 - g * g);
  const double a = x0 - X, b = (-Y * kFrequency + g * a) / wd;
  return std::exp(-g * t) * (a * std::cos(wd * t) + b * std::sin(wd * t)) + X * std::cos(kFrequency * t) +
         Y * std::sin(kFrequency * t);
}

// Its velocity x'(t), differentiated by hand.
inline double damped_exact_velocity(double t, double x0, double amplitude) {
  const double k = 1.0 - kFrequency * kFrequency, den = k * k + kDamping * kDamping * kFrequency * kFrequency;
  const double X = amplitude * k / den, Y = amplitude * kDamping * kFrequency / den;
  const double g = kDamping / 2, wd = std::sqrt(1.0 - g * g);
  const double a = x0 - X, b = (-Y * kFrequency + g * a) / wd;
  const double c = std::cos(wd * t), s = std::sin(wd * t);
  return std::exp(-g * t) * (-g * (a * c + b * s) + wd * (-a * s + b * c)) +
         kFrequency * (-X * std::sin(kFrequency * t) + Y * std::cos(kFrequency * t));
}

}  // namespace varia::testing
