// SPDX-License-Identifier: BSD-3-Clause
// Constant-velocity pose Kalman filter with error-state orientation (docs/tracking.md 9.5).
#include "tofnav/tracking/pose_filter.hpp"

#include <cmath>

#include "tofnav/core/require.hpp"
#include "tofnav/core/rotation_vector.hpp"

namespace tofnav {
namespace {

constexpr double kInitialRateVariance = 1e6;  // unknown velocity at (re-)initialisation

}  // namespace

void PoseFilterOptions::Check() const {
  Require(position_accel_sigma_mm_per_s2 > 0.0 && rotation_accel_sigma_rad_per_s2 > 0.0,
          "PoseFilterOptions: accel sigmas must be > 0");
  Require(position_sigma_mm > 0.0 && rotation_sigma_rad > 0.0,
          "PoseFilterOptions: measurement sigmas must be > 0");
  Require(gate_chi2 > 0.0 && gate_floor_mm >= 0.0 && gate_floor_rad >= 0.0,
          "PoseFilterOptions: gate_chi2 must be > 0 and the floors >= 0");
  Require(
      boost_chi2 > 0.0 && boost_velocity_sigma_mm_per_s >= 0.0 && boost_rate_sigma_rad_per_s >= 0.0,
      "PoseFilterOptions: boost_chi2 must be > 0 and the boost sigmas >= 0");
  Require(std::isfinite(initial_rate_sigma_rad_per_s) && initial_rate_sigma_rad_per_s > 0.0,
          "PoseFilterOptions::initial_rate_sigma_rad_per_s must be > 0");
  Require(max_gated >= 1, "PoseFilterOptions::max_gated must be >= 1");
  Require(max_gap_s > 0.0, "PoseFilterOptions::max_gap_s must be > 0");
}

PoseFilter::PoseFilter(const PoseFilterOptions& options) : options_(options) { options.Check(); }

void PoseFilter::Reset() { initialised_ = false; }

void PoseFilter::Initialise(const Rigid3d& measured, double timestamp_s,
                            const PoseFilterStep& step) {
  const double variance_scale = step.measurement_variance_scale;
  initialised_ = true;
  last_s_ = timestamp_s;
  position_mm_ = measured.translation;
  rotation_ = measured.rotation;
  velocity_mm_per_s_.setZero();
  angular_velocity_rad_per_s_.setZero();
  const double sp = options_.position_sigma_mm, sr = options_.rotation_sigma_rad;
  const double rate = options_.initial_rate_sigma_rad_per_s;
  position_cov_ = {variance_scale * step.position_variance_scale * sp * sp, 0.0,
                   kInitialRateVariance};
  rotation_cov_ = {variance_scale * step.rotation_variance_scale * sr * sr, 0.0, rate * rate};
  gated_in_a_row_ = 0;
  init_variance_scale_ = variance_scale;
  only_initialised_ = true;
}

std::optional<Rigid3d> PoseFilter::Predict(double timestamp_s) const {
  if (!initialised_) return std::nullopt;
  const double dt = timestamp_s - last_s_;
  if (dt < 0.0 || dt > options_.max_gap_s) return std::nullopt;
  return Rigid3d(FromRotationVector(angular_velocity_rad_per_s_ * dt) * rotation_,
                 position_mm_ + velocity_mm_per_s_ * dt);
}

PoseFilterUpdate PoseFilter::Update(const Rigid3d& measured, double timestamp_s,
                                    const PoseFilterStep& step) {
  const double measurement_variance_scale = step.measurement_variance_scale;
  Require(std::isfinite(measurement_variance_scale) && measurement_variance_scale >= 1.0 &&
              std::isfinite(step.position_variance_scale) && step.position_variance_scale >= 1.0 &&
              std::isfinite(step.rotation_variance_scale) && step.rotation_variance_scale >= 1.0,
          "PoseFilter::Update: the variance scales must be >= 1");
  const std::optional<Rigid3d> predicted = Predict(timestamp_s);
  if (!predicted) {  // first measurement, a gap, or time going backwards
    Initialise(measured, timestamp_s, step);
    return {measured, false, true};
  }
  const double dt = timestamp_s - last_s_;
  const double accel_sigma = step.position_accel_sigma_mm_per_s2 > 0.0
                                 ? step.position_accel_sigma_mm_per_s2
                                 : options_.position_accel_sigma_mm_per_s2;
  const RateCovariance pos = PropagateConstantVelocity(position_cov_, dt, accel_sigma);
  const RateCovariance rot =
      PropagateConstantVelocity(rotation_cov_, dt, options_.rotation_accel_sigma_rad_per_s2);
  const double sp = options_.position_sigma_mm, sr = options_.rotation_sigma_rad;
  const double r_pos = measurement_variance_scale * step.position_variance_scale * sp * sp;
  const double r_rot = measurement_variance_scale * step.rotation_variance_scale * sr * sr;
  const double s_pos = pos.pp + r_pos, s_rot = rot.pp + r_rot;
  const Eigen::Vector3d innovation_pos = measured.translation - predicted->translation;
  const Eigen::Vector3d innovation_rot =
      RotationVector(measured.rotation * predicted->rotation.inverse());
  const double chi2_rot = step.gate_on_rotation ? innovation_rot.squaredNorm() / s_rot : 0.0;
  const double chi2 = innovation_pos.squaredNorm() / s_pos + chi2_rot;
  const bool beyond_floor =
      innovation_pos.norm() > options_.gate_floor_mm ||
      (step.gate_on_rotation && innovation_rot.norm() > options_.gate_floor_rad);
  if (chi2 > options_.gate_chi2 && beyond_floor) {
    // A state started from one measurement that fitted worse than this one does not lock the
    // better one out: start again from it.
    const bool poor_start = only_initialised_ && measurement_variance_scale < init_variance_scale_;
    if (!poor_start && ++gated_in_a_row_ < options_.max_gated) return {*predicted, true, false};
    Initialise(measured, timestamp_s, step);  // a real jump
    return {measured, false, true};
  }
  gated_in_a_row_ = 0;
  only_initialised_ = false;
  const RateCovarianceUpdate up = MeasureValue(pos, r_pos);
  const RateCovarianceUpdate ur = MeasureValue(rot, r_rot);
  position_mm_ = predicted->translation + up.value_gain * innovation_pos;
  velocity_mm_per_s_ += up.rate_gain * innovation_pos;
  rotation_ =
      (FromRotationVector(ur.value_gain * innovation_rot) * predicted->rotation).normalized();
  angular_velocity_rad_per_s_ += ur.rate_gain * innovation_rot;
  position_cov_ = up.posterior;
  rotation_cov_ = ur.posterior;
  if (innovation_pos.squaredNorm() / s_pos > options_.boost_chi2) {  // a manoeuvre starts
    position_cov_.vv +=
        options_.boost_velocity_sigma_mm_per_s * options_.boost_velocity_sigma_mm_per_s;
  }
  if (innovation_rot.squaredNorm() / s_rot > options_.boost_chi2) {
    rotation_cov_.vv += options_.boost_rate_sigma_rad_per_s * options_.boost_rate_sigma_rad_per_s;
  }
  last_s_ = timestamp_s;
  return {Rigid3d(rotation_, position_mm_), false, false, up.value_gain};
}

}  // namespace tofnav
