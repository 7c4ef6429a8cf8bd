// SPDX-License-Identifier: BSD-3-Clause
// Pivot calibration of a tracked instrument: its tip in its own marker frame, from poses taken
// while the tip rests in a divot and the instrument swings about it (docs/tracking.md,
// "Pivot calibration").
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <span>

#include "tofnav/core/rigid3d.hpp"

namespace tofnav {

struct PivotCalibrationOptions {
  std::size_t min_poses = 10;
  /// Least swing of the instrument about the pivot: the tip along the shaft is only known from
  /// rotations that tilt the shaft (SlicerIGT and PLUS users sweep about 30 deg or more).
  double min_angular_range_rad = 0.5235988;  // 30 deg
  /// Poses whose residual exceeds this many times the RMS are dropped and the fit repeated (up
  /// to `max_refits` times; a mis-tracked frame must not pull the tip). 0: keep every pose.
  double outlier_factor = 3.0;  // dimensionless
  int max_refits = 3;
  void Check() const;  // throws PreconditionError naming the bad field
};

enum class PivotStatus {
  kOk,
  kTooFewPoses,        // fewer than min_poses
  kTooLittleRotation,  // angular range below min_angular_range_rad (the estimate is unreliable)
};
const char* ToString(PivotStatus status);

struct PivotCalibrationResult {
  PivotStatus status = PivotStatus::kTooFewPoses;
  Eigen::Vector3d tip_in_instrument = Eigen::Vector3d::Zero();
  Eigen::Vector3d pivot_in_reference = Eigen::Vector3d::Zero();
  double rms_mm = 0.0;  // RMS over poses of |reference_from_instrument * tip - pivot|
  double max_residual_mm = 0.0;
  /// Largest angle between two poses' shaft directions (pivot -> instrument origin) [rad].
  double angular_range_rad = 0.0;
  std::size_t poses = 0;     // given
  std::size_t outliers = 0;  // dropped by the refits (the figures above are over the rest)
};

/// Least squares over every pose i of R_i tip + t_i = pivot (6 unknowns, 3 equations per pose),
/// with reference_from_instrument_i = (R_i, t_i), refitted without outliers. The estimates are
/// filled for every status but kTooFewPoses.
PivotCalibrationResult CalibratePivot(std::span<const Rigid3d> reference_from_instrument,
                                      const PivotCalibrationOptions& options = {});

}  // namespace tofnav
