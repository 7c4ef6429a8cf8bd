// SPDX-License-Identifier: BSD-3-Clause
// One constant-velocity pose filter per tool: real time steps, reset, gate (docs/tracking.md 9.5).
#pragma once

#include <optional>

#include "tofnav/core/rigid3d.hpp"
#include "tofnav/tracking/constant_velocity.hpp"

namespace tofnav {

struct PoseFilterOptions {
  /// White-acceleration process noise: lower is smoother and lags more (the jitter knob).
  double position_accel_sigma_mm_per_s2 = 3.0;
  double rotation_accel_sigma_rad_per_s2 = 0.05;
  /// Measurement noise of a raw pose, per axis.
  double position_sigma_mm = 0.15;
  double rotation_sigma_rad = 0.003;
  /// Innovation gate: chi-square with 6 degrees of freedom (22.46: p = 0.999). Innovations below
  /// both floors are never gated, so slow manoeuvres are followed, not rejected.
  double gate_chi2 = 22.46;
  double gate_floor_mm = 3.0;
  double gate_floor_rad = 0.035;
  /// Manoeuvre boost: a normalised position (rotation) innovation above boost_chi2 (3 degrees
  /// of freedom; 16.27: p = 0.999) adds boost_*_sigma^2 to the rate variance, so the filter
  /// catches up with a starting motion in a few frames while a still tool stays smooth.
  double boost_chi2 = 16.27;
  double boost_velocity_sigma_mm_per_s = 300.0;
  double boost_rate_sigma_rad_per_s = 3.0;
  /// Rotation rate uncertainty at (re-)initialisation: unknown by default (the first two
  /// measurements set the rate); a filter in a frame where the tool stands still (world) knows
  /// it is small.
  double initial_rate_sigma_rad_per_s = 1000.0;
  int max_gated = 3;       // after this many consecutive gated measurements: re-initialise
  double max_gap_s = 0.2;  // no accepted measurement for longer: re-initialise on the next
  void Check() const;      // throws std::invalid_argument naming the bad field
};

/// What one measurement did to the filter.
struct PoseFilterUpdate {
  Rigid3d filtered;    // the filtered pose at the measurement time (the measurement on reset)
  bool gated = false;  // measurement rejected: `filtered` is the prediction, state unchanged
  bool reset = false;  // (re-)initialised from this measurement
  /// The filtered position's variance relative to the measurement's: the position's Kalman gain
  /// (1 on reset, when the output is the measurement; small when the filter averages many).
  double position_variance_ratio = 1.0;
};

/// What the caller knows about one measurement beyond the options.
struct PoseFilterStep {
  /// > 0 replaces the option's white acceleration for this step (the caller knows the tool moves
  /// in the measurement frame, e.g. a world-fixed tool seen by a moving camera).
  double position_accel_sigma_mm_per_s2 = 0.0;
  /// >= 1 multiplies this measurement's noise variances: a pose whose marker fit left residuals
  /// larger than the noise model predicts counts for less.
  double measurement_variance_scale = 1.0;
  /// >= 1 multiplies the position's noise variance alone (on top of the above): a marker's range
  /// noise, along the view ray, grows faster with range than the orientation's.
  double position_variance_scale = 1.0;
  /// >= 1 multiplies the orientation's noise variance alone (on top of measurement_variance_scale).
  double rotation_variance_scale = 1.0;
  /// false: the gate judges the position alone (another filter judges the orientation, e.g. one
  /// in the world frame, where a patient-fixed tool stands still while the head-worn camera turns).
  bool gate_on_rotation = true;
};

/// Constant-velocity Kalman filter on position (3 decoupled axes) and orientation (error state:
/// rotation vector about the estimate, and angular velocity), with the real time step between
/// measurements (AHAT rates drop from 45 to 5 Hz). Starts from the first measurement (no
/// swim-in), re-initialises after a gap or repeated gating.
class PoseFilter {
 public:
  explicit PoseFilter(const PoseFilterOptions& options = {});

  /// One measurement with this step's `PoseFilterStep`.
  PoseFilterUpdate Update(const Rigid3d& measured_ahat_from_tool, double timestamp_s,
                          const PoseFilterStep& step = {});
  /// The state extrapolated to `timestamp_s`; nullopt before the first measurement or when the
  /// gap exceeds max_gap_s (the filter would re-initialise).
  std::optional<Rigid3d> Predict(double timestamp_s) const;
  void Reset();
  bool initialised() const { return initialised_; }

 private:
  void Initialise(const Rigid3d& measured, double timestamp_s, const PoseFilterStep& step);

  PoseFilterOptions options_;
  bool initialised_ = false;
  double last_s_ = 0.0;
  Eigen::Vector3d position_mm_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity_mm_per_s_ = Eigen::Vector3d::Zero();
  Eigen::Quaterniond rotation_ = Eigen::Quaterniond::Identity();
  Eigen::Vector3d angular_velocity_rad_per_s_ = Eigen::Vector3d::Zero();  // in `ahat`
  RateCovariance position_cov_, rotation_cov_;
  int gated_in_a_row_ = 0;
  double init_variance_scale_ = 1.0;  // of the measurement the state started from
  bool only_initialised_ = false;     // no measurement accepted since (re-)initialisation
};

}  // namespace tofnav
