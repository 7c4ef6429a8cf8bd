// SPDX-License-Identifier: BSD-3-Clause
// Tracking accuracy against ground truth: pose errors, tracked fraction, identities, jitter.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <span>
#include <vector>

#include "tofnav/core/rigid3d.hpp"
#include "tofnav/core/statistics.hpp"
#include "tofnav/tracking/settling.hpp"

namespace tofnav {

/// One tool in one frame: the truth and what the tracker reported.
struct ToolEvaluationFrame {
  Rigid3d true_ahat_from_tool;
  bool fully_visible = true;        // every marker visible and apart from the others in the image
  std::optional<Rigid3d> raw;       // measured pose, when reported
  std::optional<Rigid3d> filtered;  // filtered pose, when reported
  /// The filtered orientation's expected RMS error (TrackedTool::filtered_rotation_sd_rad), when
  /// reported.
  std::optional<double> filtered_rotation_sd_rad;
};

struct TrackingEvaluationOptions {
  /// A raw pose farther from the truth than either is a wrong identity (another tool, a mirror
  /// or a symmetric flip), counted apart and left out of the error statistics.
  double wrong_translation_mm = 10.0;
  double wrong_rotation_rad = 0.174532925199;  // 10 degrees
  /// Consecutive frames whose true pose moves less than this are one static run [mm, rad].
  double static_translation_mm = 1e-6;
  double static_rotation_rad = 1e-9;
  int jitter_warmup_frames = 20;  // frames dropped at the start of a static run (filter settling)
  int min_static_frames = 10;     // frames a static run needs after the warm-up
  double range_bin_mm = 100.0;    // width of the marker-range bins of the range bias
  /// A filtered pose whose filtered_rotation_sd_rad is above this is SETTLING, as navigation
  /// flags it (NavigatorOptions::settled_rotation_sd_rad; docs/navigation.md 1.2) [rad].
  double settled_rotation_sd_rad = kSettledRotationSdRad;
  void Check() const;  // throws std::invalid_argument naming the bad field
  /// A measured pose farther from the true one than wrong_translation_mm or wrong_rotation_rad.
  bool IsWrongIdentity(const Rigid3d& measured, const Rigid3d& truth) const;
};

/// Errors of the poses compared (wrong identities excluded); count: the poses (the same in both).
struct PoseErrorStats {
  Summary position_mm;   // translation error
  Summary rotation_deg;  // rotation angle error
  /// Standard errors of the two RMS over the frames in record order (RmsStandardError: how far
  /// another run of the same process would put them); NaN with fewer than 4 poses.
  double position_rms_se_mm = 0.0, rotation_rms_se_deg = 0.0;
};

/// Mean signed range error |T_est m| - |T_true m| of the tool's marker centres, per bin of true
/// centre range (raw poses).
struct RangeBiasBin {
  double from_mm = 0.0, to_mm = 0.0;
  double mean_bias_mm = 0.0;
  int count = 0;
};

struct ToolEvaluation {
  int frames = 0;
  int posed_frames = 0;  // frames with a raw pose
  int fully_visible_frames = 0;
  int tracked_fully_visible = 0;  // of those, frames with a correct raw pose
  double tracked_fraction = 0.0;  // tracked_fully_visible / fully_visible_frames (0 when none)
  int wrong_identities = 0;       // raw poses beyond the wrong-identity thresholds
  PoseErrorStats raw, filtered;
  PoseErrorStats raw_fully_visible;       // raw poses of fully visible frames only
  PoseErrorStats filtered_fully_visible;  // filtered poses of fully visible frames only
  /// ... of those, the poses that are not SETTLING (no sd, or at most settled_rotation_sd_rad):
  /// what navigation shows as settled. Reported beside the lines, never instead of them.
  PoseErrorStats filtered_settled_fully_visible;
  int settling_frames = 0;  // filtered poses that are SETTLING
  /// sqrt(trace(covariance)) of the position over static runs (pooled); nullopt without one.
  std::optional<double> jitter_raw_mm, jitter_filtered_mm;
  int static_frames = 0;  // frames that entered the jitter
  std::vector<RangeBiasBin> range_bias;
};

/// Evaluates one tool over consecutive frames. `markers_in_tool` gives the range bias (may be
/// empty). Throws std::invalid_argument on bad options.
ToolEvaluation EvaluateToolTracking(std::span<const ToolEvaluationFrame> frames,
                                    std::span<const Eigen::Vector3d> markers_in_tool,
                                    const TrackingEvaluationOptions& options = {});

}  // namespace tofnav
