// SPDX-License-Identifier: BSD-3-Clause
// Which matched markers a tool's pose uses: damaged markers left out when enough whole ones
// remain, a residual check against the noise model and leave-one-out (docs/tracking.md section 6).
#pragma once

#include <optional>
#include <span>
#include <vector>

#include "tofnav/core/point_cloud.hpp"
#include "tofnav/core/rigid3d.hpp"
#include "tofnav/markers/marker_detection.hpp"
#include "tofnav/tracking/blob_truncation.hpp"
#include "tofnav/tracking/pose_refinement.hpp"
#include "tofnav/tracking/tool_geometry.hpp"

namespace tofnav {

/// How one tool marker entered the frame's pose.
enum class MarkerUse {
  kUsed,                // matched and whole: in the pose
  kUsedDamaged,         // matched, occluded or near another blob, in the pose as it is: too few
                        // whole markers to leave it out (the residual check may still drop it)
  kUnseen,              // no detection matched it (hidden, out of view, or too faint)
  kDroppedOccluded,     // matched, but its rim borders something in front of it: left out
  kDroppedNearBlob,     // matched, but another blob touches it: left out
  kDroppedOutlier,      // matched, but inconsistent with the others (leave-one-out): left out
  kDroppedImageBorder,  // not matched: a blob cut by the image border lies where the pose puts it
  kDroppedMerged,       // not matched: a merged blob lies where the pose puts it
};
const char* ToString(MarkerUse use);
/// The pose holds the marker (kUsed, kUsedDamaged).
bool InPose(MarkerUse use);

struct RobustPoseOptions {
  /// Leave damaged markers (MarkerDamage::Any) out when max(3, min_visible) whole ones remain.
  /// Off by default: a flagged marker's centroid is usually still good to a few tenths of a
  /// millimetre, and a pose on one marker fewer is worse (docs/tracking.md 6); the residual check
  /// still drops a damaged marker that disagrees with the others.
  bool drop_damaged = false;
  /// Check the used markers' residuals against the noise model; with >= 4 markers, leave out
  /// the one whose removal makes the rest consistent (3 markers cannot tell which is wrong).
  bool check_outliers = true;
  /// Noise model of the check: lateral sigma PoseRefinementOptions::lateral_sigma_px, range sigma
  /// 1.4826 MAD / sqrt(n) of the core ranges, at least this floor [mm] (AHAT's 1 mm range steps
  /// and the f_rf residual, ~0.2 mm, make smaller MADs untrustworthy).
  double range_sigma_floor_mm = 0.5;
  /// Isotropic sigma of detections without a pixel pitch (hand-made, Kabsch only) [mm].
  double isotropic_sigma_mm = 0.5;
  /// Standard-normal quantile of the chi-square test (Wilson-Hilferty): 3.09 fails a clean frame
  /// about once in 1000.
  double check_quantile_z = 3.09;
  /// Noise model of the pose's reported sds (RobustPose::rotation_sd_rad): one pixel's range sd
  /// sigma (range / at)^exponent, a marker's that over the square root of its core pixels, and
  /// the check's lateral sigma. The defaults are a real HoloLens 2's (STTAR, docs/tracking.md 3):
  /// 0.3 mm at 350 mm, growing as range^1.5.
  double pixel_range_sigma_mm = 0.3;
  double pixel_range_sigma_at_mm = 350.0;
  double pixel_range_sigma_exponent = 1.5;
  /// A blob smaller than its siblings weighs less across its ray, in the fit, the check and the
  /// sds (blob_truncation.hpp).
  BlobTruncationOptions truncation;
  void Check() const;  // throws std::invalid_argument naming the bad field
};

struct RobustPose {
  Rigid3d ahat_from_tool;
  std::vector<MarkerUse> use;        // per tool marker
  std::vector<double> residuals_mm;  // |pose * m - centre| per used marker, tool marker order
  double fre_rms_mm = 0.0;           // RMS of residuals_mm
  double chi2 = 0.0;                 // sum of the used markers' squared normalised residuals
  double chi2_limit = 0.0;           // what the noise model allows for 3 n - 6 degrees of freedom
  bool outliers_checked = false;     // >= 4 markers were used, so a wrong one could be found
  /// Per-axis standard deviations of the pose under the sds' noise model (RayRangePoseCovariance:
  /// square roots of the rotation's and the translation's mean variance); 0 where the markers
  /// do not fix it.
  double rotation_sd_rad = 0.0;
  double position_sd_mm = 0.0;
};

/// The pose of a tool matched to `detections` (`marker_detection`: per tool marker, an index
/// into the detections or -1; `centres`: the detections' centres for this tool) from the markers
/// it should use: Kabsch on them, then RefineToolPose when refinement.enabled.
RobustPose FitToolMarkers(std::span<const DetectedMarker> detections,
                          std::span<const int> marker_detection, const ToolGeometry& tool,
                          const Points3d& centres, const PoseRefinementOptions& refinement,
                          const RobustPoseOptions& options);

/// Marks every kUnseen marker whose posed centre falls on a dropped blob (within the blob's
/// angular radius plus the marker's) with that blob's reason.
void ExplainUnseenMarkers(const Rigid3d& ahat_from_tool, const ToolGeometry& tool,
                          std::span<const DroppedBlob> dropped, std::vector<MarkerUse>& use);

}  // namespace tofnav
