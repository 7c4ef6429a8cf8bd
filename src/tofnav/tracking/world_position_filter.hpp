// SPDX-License-Identifier: BSD-3-Clause
// The position of a tool that stands still in the world, fused with each frame's measurement
// through the headset's pose, whose jitter the innovations measure (docs/tracking.md 1).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <span>
#include <vector>

#include "tofnav/core/rigid3d.hpp"

namespace tofnav {

struct WorldPositionOptions {
  /// Noise of a raw tool position (its markers' centroid) along and across the view ray at
  /// noise_range_mm, per axis, growing as (range / noise_range_mm)^exponent: the markers' ToF
  /// ranges fix it along the ray, their sub-pixel rays across it. One pixel's range sd grows as
  /// range^1.5 and a marker covers range^-2 pixels, hence 2.5 along; across, the measured growth
  /// (reference plates of 58 spent suite sessions, raw, per 100 mm of range: along 0.11 / 0.15 /
  /// 0.21 / 0.28 / 0.42 mm RMS, across 0.041 / 0.059 / 0.074 / 0.095 / 0.127 per axis at 350-750
  /// mm; docs/tracking.md 1, "What bounds the position line").
  double along_ray_sigma_mm = 0.20;
  double across_ray_sigma_mm = 0.075;
  double noise_range_mm = 550.0;
  double along_ray_exponent = 2.5;
  double across_ray_exponent = 1.5;
  /// The tool's motion in the world: constant velocity with this white acceleration, starting
  /// (at each (re-)initialisation) from rest with this speed sd. A tool fixed to the patient's
  /// head drifts with it, slowly and steadily (a head settling on its support: about 1 mm/s, the
  /// simulator's drift cases); a real move is gated and restarts the filter. A looser model
  /// (0.3 mm/s^2, 5 mm/s until session 46) held the position no better than a few frames of a
  /// 6 Hz session with look-aways do (docs/tracking.md 1).
  double accel_sigma_mm_per_s2 = 0.1;
  double initial_speed_sigma_mm_per_s = 1.0;
  double max_gap_s = 5.0;    // no accepted measurement for longer: re-initialise on the next
  double gate_chi2 = 16.27;  // innovation gate, chi-square with 3 degrees of freedom: p = 0.999
  int max_gated = 3;         // after this many consecutive gated measurements: re-initialise
  /// The rig pose's error at a tool, per axis: assumed this large at first (little weight on the
  /// prediction), then measured from the innovations across the view ray, where a marker
  /// measurement is precise, over about jitter_window measurements, never below the minimum.
  double initial_jitter_sigma_mm = 1.0;
  double min_jitter_sigma_mm = 0.1;
  int jitter_window = 32;
  void Check() const;  // throws std::invalid_argument naming the bad field
};

/// The headset pose's per-frame error where the tools are, per axis [mm^2]: one estimate per
/// tracker, since every tool of a frame is placed by the same rig pose.
class RigJitterEstimate {
 public:
  explicit RigJitterEstimate(const WorldPositionOptions& options = {});
  double variance_mm2() const { return variance_mm2_; }
  /// One innovation's sample of the variance (may be negative: noise), as a running mean over
  /// the last ~jitter_window samples.
  void Add(double sample_mm2);
  void Reset();

 private:
  WorldPositionOptions options_;
  double variance_mm2_ = 0.0;
  int count_ = 0;
};

/// One frame's measurement of the point, and the caller's own estimate of it at that time.
struct WorldPositionInput {
  Eigen::Vector3d measured_in_ahat = Eigen::Vector3d::Zero();  // this frame's raw point
  double variance_scale = 1.0;  // >= 1 multiplies its noise (a poor marker fit)
  /// Fused with the prediction: the caller's estimate (e.g. the `ahat` filter's, which averages
  /// while the camera stands still) and its variance relative to the raw point's (1: the raw
  /// point itself).
  Eigen::Vector3d estimate_in_ahat = Eigen::Vector3d::Zero();
  double estimate_variance_ratio = 1.0;
};

/// One world-fixed point's terms in a frame: its held world position predicted into `ahat`
/// through the frame's rig pose (the held position's covariance mapped there, the rig pose's
/// error not included) and the caller's estimate of the point with its covariance.
struct WorldPointTerms {
  Eigen::Vector3d predicted_in_ahat = Eigen::Vector3d::Zero();
  Eigen::Matrix3d held_cov_mm2 = Eigen::Matrix3d::Zero();
  Eigen::Vector3d estimate_in_ahat = Eigen::Vector3d::Zero();
  Eigen::Matrix3d estimate_cov_mm2 = Eigen::Matrix3d::Identity();
};

struct WorldPositionUpdate {
  /// The measurement fused with the held world position, in `ahat`; nullopt when the filter
  /// (re-)started from this measurement or gated it (the caller keeps its own estimate).
  std::optional<Eigen::Vector3d> fused_in_ahat;
  /// The terms fused_in_ahat was fused from (set with it): FuseWithSharedRigError fuses them
  /// again with those of the frame's other world-fixed points.
  std::optional<WorldPointTerms> terms;
  bool gated = false;
  bool reset = false;
};

/// The frame's world-fixed points fused with their predictions, the rig pose's error shared by
/// all of them (docs/tracking.md 1, "One rig pose for every tool of a frame"). Each point's
/// prediction errs by the held position's error, its own, and the rig pose's error at the tools,
/// one translation per frame with `rig_variance_mm2` per axis; each estimate by its own noise.
/// The shared error's posterior takes every point's innovation, so a point's along-ray range
/// noise is averaged with the others' where the prediction alone would carry the whole jitter.
/// With one point this is WorldPositionFilter's own fusion. A point whose innovation disagrees
/// with the shared error the others give (chi-square beyond `gate_chi2`, 3 degrees of freedom:
/// a tool that moves in the world) leaves, the worst first, and is fused alone. `joined` (if
/// given): per point, whether it shared the error with at least one other.
std::vector<Eigen::Vector3d> FuseWithSharedRigError(std::span<const WorldPointTerms> points,
                                                    double rig_variance_mm2, double gate_chi2,
                                                    std::vector<bool>* joined = nullptr);

/// Constant-velocity Kalman filter of one point's world position (a tool's markers' centroid).
/// Each frame it predicts the point in `ahat` through that frame's rig pose (its error: the
/// held position's and the rig jitter) and fuses that with the caller's estimate of the point
/// (anisotropic: the range noise lies along the ray). The two errors are independent, so the fused
/// point beats both: the measurement across the ray, the prediction along it where the range is
/// poor.
class WorldPositionFilter {
 public:
  explicit WorldPositionFilter(const WorldPositionOptions& options = {});
  /// The world position is updated with the raw point; the output fuses the caller's estimate.
  WorldPositionUpdate Update(const WorldPositionInput& input, const Rigid3d& world_from_ahat,
                             double timestamp_s, RigJitterEstimate& jitter);
  void Reset();
  bool initialised() const { return initialised_; }

 private:
  void Initialise(const Eigen::Vector3d& measured_in_world, const Eigen::Matrix3d& noise_in_world,
                  double timestamp_s);

  WorldPositionOptions options_;
  bool initialised_ = false;
  double last_s_ = 0.0;
  int gated_in_a_row_ = 0;
  Eigen::Matrix<double, 6, 1> state_ = Eigen::Matrix<double, 6, 1>::Zero();  // mm, mm/s
  Eigen::Matrix<double, 6, 6> cov_ = Eigen::Matrix<double, 6, 6>::Zero();
};

}  // namespace tofnav
