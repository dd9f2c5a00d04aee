// Chaos indicators from the tangent map (spec "Tangent maps and ensembles"), along a run whose
// deviation vector w_k = M_k w_{k-1} / |M_k w_{k-1}| the trajectory driver propagates by the
// map's exact tangent map M_k (trajectory.hpp), with r_k = |M_k w_{k-1}| its growth in step k:
// - the largest Lyapunov exponent's running estimate lambda(t_k) = (1/t_k) sum_{j<=k} ln r_j;
// - MEGNO, the mean exponential growth factor of nearby orbits (Cincotta & Simo 2000; for maps,
//   Cincotta, Giordano & Simo 2003): Y(t_k) = (2/t_k) sum_{j<=k} t_j ln r_j and its mean
//   <Y>(t_k) = (1/t_k) sum_{j<=k} (t_j - t_{j-1}) Y(t_j), the value reported. <Y> -> 0 on a
//   stable periodic orbit of an isochronous system (|w| stays bounded), -> 2 on a quasi-periodic
//   orbit (|w| grows linearly), and grows like lambda t / 2 on a chaotic one.
// t is the time since the run's start.
#pragma once

#include <cmath>

namespace varia {

class ChaosIndicators {
 public:
  // The step that ended at time t (> the last one's) grew the deviation by exp(log_growth).
  void add(double t, double log_growth) {
    log_sum_ += log_growth;
    weighted_sum_ += t * log_growth;
    const double Y = 2.0 * weighted_sum_ / t;
    mean_sum_ += (t - t_) * Y;
    t_ = t;
  }
  // <Y>(t) and lambda(t) at the last step; 0 before the first.
  double megno() const { return t_ > 0.0 ? mean_sum_ / t_ : 0.0; }
  double lyapunov() const { return t_ > 0.0 ? log_sum_ / t_ : 0.0; }

 private:
  double t_ = 0.0, log_sum_ = 0.0, weighted_sum_ = 0.0, mean_sum_ = 0.0;
};

}  // namespace varia
