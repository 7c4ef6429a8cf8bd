// SPDX-License-Identifier: BSD-3-Clause
// Constant-velocity covariance propagation and update (docs/tracking.md 9.5).
#include "tofnav/tracking/constant_velocity.hpp"

namespace tofnav {

RateCovariance PropagateConstantVelocity(const RateCovariance& p, double dt_s, double accel_sigma) {
  const double q = accel_sigma * accel_sigma, dt2 = dt_s * dt_s;
  RateCovariance out;
  out.pp = p.pp + 2.0 * dt_s * p.pv + dt2 * p.vv + q * dt2 * dt2 / 4.0;
  out.pv = p.pv + dt_s * p.vv + q * dt2 * dt_s / 2.0;
  out.vv = p.vv + q * dt2;
  return out;
}

RateCovarianceUpdate MeasureValue(const RateCovariance& predicted, double measurement_variance) {
  const double s = predicted.pp + measurement_variance;
  RateCovarianceUpdate u;
  u.value_gain = predicted.pp / s;
  u.rate_gain = predicted.pv / s;
  // P = (I - K H) P for H = [1 0].
  u.posterior = {(1.0 - u.value_gain) * predicted.pp, (1.0 - u.value_gain) * predicted.pv,
                 predicted.vv - u.rate_gain * predicted.pv};
  return u;
}

}  // namespace tofnav
