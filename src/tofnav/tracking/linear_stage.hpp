// SPDX-License-Identifier: BSD-3-Clause
// fit-marker-error data: range errors of a marker structure moved by a linear stage (III-A.1).
#pragma once

#include <optional>
#include <span>
#include <vector>

#include "tofnav/core/rigid3d.hpp"
#include "tofnav/markers/marker_detection.hpp"
#include "tofnav/markers/marker_range_sample.hpp"
#include "tofnav/tracking/ray_pose.hpp"
#include "tofnav/tracking/tool_geometry.hpp"
#include "tofnav/tracking/tool_pose.hpp"

namespace tofnav {

/// One frame of the stage recording.
struct StageFrame {
  double timestamp_s = 0.0;
  std::vector<DetectedMarker> markers;  // raw detections (no Eq. (2): that is being measured)
};

struct StageRangeErrorOptions {
  ToolPoseOptions pose;  // matching of the structure in each frame
  RayPoseOptions ray_pose;
  /// true: the stage moves at constant speed, so the trajectory is o + v t over the timestamps
  /// (noise removed along and across the line); false: positions are projected onto the fitted
  /// 3D line (noise removed across it only).
  bool constant_speed = true;
  /// The stage's commanded speed [mm/s], when known (constant_speed only): the line keeps the
  /// fitted direction but moves at this speed, and only its origin is fitted. PnP's depth noise
  /// (growing as range^2) otherwise leaves the fitted speed off by ~0.1 % per run, a tilt that
  /// f_rf then carries as a range-dependent bias.
  std::optional<double> known_speed_mm_per_s;
  double max_line_residual_mm = 3.0;  // frames whose PnP position is farther from the line drop
  int min_frames = 10;
  void Check() const;  // throws std::invalid_argument naming the bad field
};

struct StageRangeErrorResult {
  std::vector<MarkerRangeSample> samples;  // one per matched marker and used frame
  std::vector<int> sample_frame;           // frame index of each sample
  std::vector<int> sample_marker;          // structure marker of each sample
  Eigen::Vector3d line_origin_mm = Eigen::Vector3d::Zero();          // position at t = 0 [ahat]
  Eigen::Vector3d line_velocity_mm_per_s = Eigen::Vector3d::Zero();  // or unit direction
  Eigen::Quaterniond ahat_from_structure_rotation = Eigen::Quaterniond::Identity();  // mean
  double line_rms_mm = 0.0;  // RMS distance of the per-frame PnP positions from the line
  double fitted_speed_mm_per_s =
      0.0;  // of the free line fit (constant_speed), before any known speed
  int frames_used = 0;
};

/// Sec. III-A.1: per frame the structure is matched (EstimateToolPose on the range-based
/// centres), then posed from its marker rays alone (EstimatePoseFromRays, unbiased by ToF
/// range); the positions are fitted with a line and the rotations averaged; each marker's
/// reference centre O' gives its true surface range (SurfaceRangeForCentreMm), and
/// delta = d_measured - d_true. Throws std::invalid_argument when fewer than min_frames frames
/// give a pose.
StageRangeErrorResult MeasureMarkerRangeErrors(std::span<const StageFrame> frames,
                                               const ToolGeometry& structure,
                                               const StageRangeErrorOptions& options = {});

}  // namespace tofnav
