#include "varia/core/trajectory.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace varia {

Trajectory::Trajectory(DiscreteHamiltonianMap& map, const Eigen::VectorXd& q0, const Eigen::VectorXd& p0,
                       double t0, double h)
    : map_(map), q_(q0), p_(p0), q1_(q0.size()), p1_(p0.size()), q_start_(q0.size()), p_start_(p0.size()), t0_(t0),
      h_(h) {}

void Trajectory::track_deviation(const Eigen::VectorXd& w) {
  if (const std::string refusal = map_.tangent_map_refusal(); !refusal.empty()) throw std::logic_error(refusal);
  tracking_ = true;
  deviation_ = w.normalized();
  deviation1_.resize(w.size());
}

void Trajectory::step() {
  const double t = time_of(steps_);
  try {
    if (tracking_)
      map_.step_with_tangent(q_.data(), p_.data(), t, h_, q1_.data(), p1_.data(), 1, deviation_.data(),
                             deviation1_.data());
    else
      map_.step(q_.data(), p_.data(), t, h_, q1_.data(), p1_.data());
  } catch (const NumericalFailure& e) {
    throw StepFailure(e, steps_ + 1, t);
  }
  if (!q1_.allFinite() || !p1_.allFinite()) throw StepFailure("a non-finite state", std::nan(""), steps_ + 1, t);
  if (tracking_) {
    const double growth = deviation1_.norm();
    if (!(growth > 0.0) || !std::isfinite(growth))
      throw StepFailure("a tangent map that does not keep the deviation vector finite and nonzero", growth,
                        steps_ + 1, t);
    deviation_ = deviation1_ / growth;
    chaos_.add(time_of(steps_ + 1) - t0_, std::log(growth));
  }
  q_.swap(q1_);
  p_.swap(p1_);
  ++steps_;
}

void Trajectory::advance(long count) {
  if (tracking_) {
    for (long k = 0; k < count; ++k) step();
    return;
  }
  const long last = steps_ + count;
  try {
    map_.advance(q_.data(), p_.data(), time_of(steps_), h_, count, q1_.data(), p1_.data());
  } catch (const NumericalFailure& e) {
    throw StepFailure(e, last, time_of(last - 1));
  }
  if (!q_.allFinite() || !p_.allFinite())
    throw StepFailure("a non-finite state", std::nan(""), last, time_of(last - 1));
  steps_ = last;
}

void Trajectory::advance_checked(long count) {
  const long start = steps_;
  q_start_ = q_;
  p_start_ = p_;
  try {
    advance(count);
  } catch (const StepFailure&) {
    q_ = q_start_;
    p_ = p_start_;
    steps_ = start;
    for (long k = 0; k < count; ++k) step();  // throws the failure with its step
  }
}

}  // namespace varia
