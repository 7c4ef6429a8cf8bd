// SPDX-License-Identifier: BSD-3-Clause
// Refining a matched tool's Kabsch pose on marker rays and weighted ranges (docs/tracking.md 9.4).
#pragma once

#include <optional>
#include <span>
#include <vector>

#include "tofnav/core/point_cloud.hpp"
#include "tofnav/core/rigid3d.hpp"
#include "tofnav/markers/marker_detection.hpp"
#include "tofnav/tracking/tool_geometry.hpp"

namespace tofnav {

/// Each marker's sub-pixel ray is far more precise than its ToF range, which an isotropic Kabsch
/// fit turns into tilt; EstimatePoseFromRaysAndRanges (ray_pose.hpp) weighs the two apart.
struct PoseRefinementOptions {
  bool enabled = true;
  /// Lateral sigma of a marker centre [pixels]; times pixel pitch and range gives millimetres.
  /// With the floor below, tuned on evd-usecase: only the ratio of the two matters there, and
  /// 0.15-0.4 px per 0.6-1.5 mm give the same rotation error within 0.002 deg.
  double lateral_sigma_px = 0.25;
  /// Range sigma of a marker: 1.4826 MAD of its core ranges / sqrt(core pixels), at least this
  /// floor [mm] (AHAT ranges come in 1 mm steps; a lower floor trusts noisy MADs and loses).
  double range_sigma_floor_mm = 1.0;
  /// Flat tape on a flat plate: each core pixel's range is moved along the disc's plate (at the
  /// current pose; MarkerPlates: the whole tool, or each plate of a tool built from several)
  /// onto the marker ray, removing the range ramp of a tilted disc whose core pixels sit off its
  /// centre. Spheres and discs off any flat plate use the detected centre range.
  bool disc_plane_ranges = true;
  int passes = 2;      // refinements, each with the plane of the previous pose (disc_plane_ranges)
  void Check() const;  // throws std::invalid_argument naming the bad field
};

/// 1.4826 MAD of `values` / sqrt(n), the sigma of their mean, at least `floor_mm` (and at least
/// max(floor_mm, 1) for fewer than two values). Reorders the values.
double MeanSigmaMm(std::vector<double>& values, double floor_mm);

/// The refined ahat_from_tool of a tool matched to `detections` (`marker_detection`: per tool
/// marker, an index into the detections or -1), starting from `initial_ahat_from_tool`;
/// `centres` are the detections' centres for this tool (marker_centre.hpp). nullopt when a
/// detection lacks a pixel pitch (hand-made) or the fit does not converge.
/// `extra_lateral_sigma_mm`, per tool marker when not empty, adds in quadrature to a marker's
/// lateral sigma (a truncated blob's centroid, blob_truncation.hpp).
std::optional<Rigid3d> RefineToolPose(std::span<const DetectedMarker> detections,
                                      std::span<const int> marker_detection,
                                      const ToolGeometry& tool, const Points3d& centres,
                                      const Rigid3d& initial_ahat_from_tool,
                                      const PoseRefinementOptions& options = {},
                                      std::span<const double> extra_lateral_sigma_mm = {});

}  // namespace tofnav
