// SPDX-License-Identifier: BSD-3-Clause
// The (value, rate) covariance of a constant-velocity Kalman filter whose three axes are
// isotropic and decoupled, so one 2 x 2 covariance serves all three (docs/tracking.md 9.5).
#pragma once

namespace tofnav {

struct RateCovariance {
  double pp = 0.0, pv = 0.0, vv = 0.0;  // value, value x rate, rate
};

/// F = [1 dt; 0 1], Q = s^2 [dt^4/4 dt^3/2; dt^3/2 dt^2]: discrete white acceleration s.
RateCovariance PropagateConstantVelocity(const RateCovariance& p, double dt_s, double accel_sigma);

/// One measurement of the value (H = [1 0]) with this variance: the gains and the posterior.
struct RateCovarianceUpdate {
  double value_gain = 0.0, rate_gain = 0.0;
  RateCovariance posterior;
};
RateCovarianceUpdate MeasureValue(const RateCovariance& predicted, double measurement_variance);

}  // namespace tofnav
