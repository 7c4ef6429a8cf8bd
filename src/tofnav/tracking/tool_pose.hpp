// SPDX-License-Identifier: BSD-3-Clause
// Poses of several tools in one frame: matching, arbitration, ambiguity and status (Sec. III-C).
#pragma once

#include <Eigen/Core>
#include <limits>
#include <optional>
#include <span>
#include <vector>

#include "tofnav/core/rigid3d.hpp"
#include "tofnav/markers/marker_detection.hpp"
#include "tofnav/markers/marker_void.hpp"
#include "tofnav/tracking/correspondence.hpp"
#include "tofnav/tracking/pose_refinement.hpp"
#include "tofnav/tracking/robust_pose.hpp"
#include "tofnav/tracking/tool_geometry.hpp"

namespace tofnav {

/// Normal per-frame outcomes for one tool (docs/style.md section 3). Only kOk and
/// kPartiallyOccluded carry a pose, and that pose is always measured in this frame.
enum class ToolStatus {
  kOk,                 // every marker matched
  kPartiallyOccluded,  // matched with min_visible or more, but not all, markers
  kAmbiguous,          // two distinct poses (symmetry, twin tools, shared blobs) score alike
  kTooFewMarkers,      // fewer than min_visible detections were left for this tool
  kOutOfView,          // enough detections, but none fit the tool
};
const char* ToString(ToolStatus status);

struct ToolPoseOptions {
  MatchTolerance tolerance;
  /// After matching, RefineToolPose (needs detections: EstimateToolPoses, not EstimateToolPose).
  PoseRefinementOptions refinement;
  /// Which matched markers the pose uses: damaged ones out, outliers out (robust_pose.hpp).
  RobustPoseOptions robust;
  double max_fre_mm = 1.0;  // default FRE acceptance (ToolGeometry::max_fre_mm overrides)
  /// f_rf's entrance-angle term (MarkerRangeModel::entrance_gain_mm_per_rad): retro sheeting at
  /// entrance angle beta reads farther by gain x beta. The pose gives each matched marker's beta
  /// (a disc: its plate's normal, MarkerPlaneNormals, against its ray; a sphere: each core pixel's
  /// incidence on it); its ranges are shortened by gain x beta and the pose fitted again
  /// (EstimateToolPoses; docs/tracking.md 4). 0: none (Eq. 2 alone).
  double marker_entrance_gain_mm_per_rad = 0.0;
  double occlusion_penalty_mm = 0.5;  // score per unseen marker
  /// Temporal prior: score += prior_weight * min(mean marker distance from the predicted pose,
  /// prior_cap_mm). Dimensionless weight.
  double prior_weight = 0.1;
  double prior_cap_mm = 10.0;
  /// A second candidate with a distinct pose scoring within this margin makes the tool ambiguous.
  double ambiguity_margin_mm = 0.3;
  double distinct_rotation_rad = 0.1;  // poses differing by more than either are distinct
  double distinct_translation_mm = 3.0;
  int max_search_nodes = 200000;  // per tool; a truncated search reports kAmbiguous
  /// Refuse candidates that put an unmatched marker in empty space, when the caller gives the
  /// frame's images (EstimateToolPoses' void_test; docs/tracking.md 6).
  bool refuse_void_poses = true;
  void Check() const;  // throws std::invalid_argument naming the bad field
};

struct ToolPoseResult {
  ToolStatus status = ToolStatus::kOutOfView;
  std::optional<Rigid3d> ahat_from_tool;  // only for kOk and kPartiallyOccluded
  std::vector<int> marker_detection;      // per tool marker: index into the detections, -1 unseen
  int visible_markers = 0;                // tool markers matched
  /// Per tool marker: in the pose, or why not (docs/tracking.md section 6); all kUnseen
  /// without a pose.
  std::vector<MarkerUse> marker_use;
  int used_markers = 0;     // markers in the pose (InPose)
  double fre_rms_mm = 0.0;  // RMS of residuals_mm
  /// |ahat_from_tool * m - centre| per marker in the pose, in tool marker order [mm]
  std::vector<double> residuals_mm;
  /// Sum of the used markers' squared residuals in noise-model sigmas, and the limit the check
  /// held it to (RobustPose); outliers_checked is false with 3 markers (they cannot be checked).
  double noise_chi2 = 0.0;
  double noise_chi2_limit = 0.0;
  bool outliers_checked = false;
  /// Per-axis sds of the pose under the noise model (RobustPose); 0 where unknown.
  double rotation_sd_rad = 0.0;
  double position_sd_mm = 0.0;
  int candidate_count = 0;  // candidates the search found for this tool
  /// Candidates refused because the frame's images show no marker, and nothing that could hide
  /// one, where they put an unmatched marker (MarkerVoidTest; docs/tracking.md 6).
  int candidates_refused_void = 0;
  /// Score gap to the best distinct alternative (infinity when there is none) [mm].
  double second_best_margin_mm = std::numeric_limits<double>::infinity();
};

/// Matches every tool against one frame's detections (centres from each tool's own marker
/// radius), scores candidates by FRE + occlusion penalty + temporal prior, assigns detections to
/// tools greedily by score (each detection to at most one tool) and flags ambiguity instead of
/// guessing. `predicted_ahat_from_tool` is empty or has one (optional) entry per tool. Each pose
/// is then fitted to the markers it should use (FitToolMarkers: damaged and inconsistent ones
/// left out); an unseen marker on a `dropped` blob (MarkerDetectionResult::dropped) says so.
/// With `void_test` (the frame's images), a candidate that leaves a marker unmatched where the
/// images show empty space in front of a far surface is never accepted (a wrong triangle of a
/// four-marker plate puts its fourth marker there) but still rivals the others, so the test only
/// takes poses away. Calls Check() on the options and every tool (throws std::invalid_argument).
std::vector<ToolPoseResult> EstimateToolPoses(
    std::span<const DetectedMarker> detections, std::span<const ToolGeometry> tools,
    std::span<const std::optional<Rigid3d>> predicted_ahat_from_tool = {},
    const ToolPoseOptions& options = {}, std::span<const DroppedBlob> dropped = {},
    const MarkerVoidTest* void_test = nullptr);

/// One tool from marker centres already in `ahat` (e.g. after Eq. (2) and the radius).
ToolPoseResult EstimateToolPose(std::span<const Eigen::Vector3d> centres_in_ahat,
                                const ToolGeometry& tool, const ToolPoseOptions& options = {});

}  // namespace tofnav
