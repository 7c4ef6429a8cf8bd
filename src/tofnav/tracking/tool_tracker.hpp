// SPDX-License-Identifier: BSD-3-Clause
// Frame-to-frame tracking of several tools: poses, temporal prior, one filter per tool, status.
#pragma once

#include <deque>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "tofnav/markers/marker_detection.hpp"
#include "tofnav/tracking/pose_filter.hpp"
#include "tofnav/tracking/tool_pose.hpp"
#include "tofnav/tracking/world_orientation_filter.hpp"
#include "tofnav/tracking/world_position_filter.hpp"

namespace tofnav {

struct ToolTrackerOptions {
  ToolPoseOptions pose;
  PoseFilterOptions filter;
  bool filter_enabled = true;
  /// With the camera's world pose (Track's world_from_ahat), the orientation is filtered in the
  /// world frame, where a tool fixed to the patient stands still while the head-worn camera turns
  /// at 10-30 deg/s: the constant-velocity filter then averages the per-frame tilt noise of a
  /// small tool instead of lagging the head. The filter restarts when the world pose comes or
  /// goes.
  bool rotation_in_world = true;
  /// ... and the position: each frame's measured markers' centroid is fused with the one held in
  /// the world, predicted through the frame's rig pose (WorldPositionFilter; the rig pose's jitter
  /// measured from the innovations). Until it holds a position, and when it gates one, the
  /// `ahat` filter's position is used. Off: the `ahat` filter's alone.
  bool position_in_world = true;
  /// ... with the rig pose's error shared by the frame's world-fixed tools: one headset pose
  /// places them all, so each tool's innovation measures that error for the others too
  /// (FuseWithSharedRigError). Off: each tool fused with its prediction alone.
  bool share_rig_error = true;
  WorldPositionOptions world_position;
  /// The world-frame orientation filter bridges gaps up to this long (dropped frames, a hand
  /// over the tool): there the tool stands still, so the held orientation stays valid where the
  /// `ahat` filter (filter.max_gap_s) must restart from one raw pose.
  double world_max_gap_s = 5.0;
  /// The turning model of the world orientation filter (WorldOrientationFilter) starts with,
  /// and boosts a large innovation by, at most this rate uncertainty: a
  /// tool fixed to the patient turns in `world` only with the patient's slow motion, so a few
  /// bad measurements cannot set it turning (a real turn is gated, then restarts the filter).
  double world_rate_sigma_rad_per_s = 0.003;
  /// ... and its rate wanders with at most this white angular acceleration. Both at 0.003 (0.17
  /// deg/s, deg/s^2) average more frames than 0.01 did: the suite's worst filtered rotation RMS
  /// 0.42 -> 0.32 deg over 48 sessions; a tool that turns at 5 deg/s seen at 45 Hz is followed
  /// within 0.8 deg (docs/tracking.md 1, `tofnav track`).
  double world_accel_sigma_rad_per_s2 = 0.003;
  /// Those two figures describe the tool while it turns with the patient. While it stands still
  /// (most of the time) its orientation in `world` changes only by the headset's slow drift: a
  /// second, still model at this rate and acceleration (0.0003 rad/s: a degree a minute) is
  /// mixed with the turning one by how well each predicts (WorldOrientationFilter: still for
  /// world_still_dwell_s, turning for world_turning_dwell_s on average). 0: the turning model
  /// alone.
  double world_still_sigma_rad_per_s = 0.0003;
  double world_still_dwell_s = 60.0;
  double world_turning_dwell_s = 2.0;
  /// With the camera's world pose over the last camera_motion_baseline_s, a world-fixed tool
  /// moves in `ahat` at the apparent speed v the camera's motion gives it; the head's wander is
  /// smooth (sinusoids up to ~0.45 Hz), so its apparent acceleration is about this bandwidth times
  /// v. The position filter's process noise is raised to that for the step: it follows the turning
  /// camera and keeps its static smoothing when the camera is still. 0 turns it off.
  double camera_motion_bandwidth_per_s = 3.0;
  /// The camera's motion is taken between poses this far apart: the rig pose's per-frame jitter
  /// (0.3 mm, 3e-4 rad in the simulator: ~20 mm/s frame to frame) would look like motion.
  double camera_motion_baseline_s = 0.4;
  /// A raw pose whose marker fit left more residual than the noise model predicts (its
  /// noise_chi2 over the 3n - 6 degrees of freedom of n markers, when above 1) enters the filters
  /// with its noise variances multiplied by that ratio: a sphere cut by a silhouette or a
  /// multipath range that survived the marker checks tilts the held pose less
  /// (docs/tracking.md 6).
  bool inflate_noise_by_fit = true;
  /// A pose matched on fewer than all of the tool's markers (kPartiallyOccluded): its noise
  /// variances times this in the world filters, which hold a still tool's pose (the `ahat`
  /// filter must follow a hand-held tool, whose hand often hides a marker: scaled there too, it
  /// lagged a pointer at rest by 0.35 mm, tests/verify_cli_test.sh). The marker that is missing is
  /// at an occluder's edge or the image's, where the others' blobs are clipped too, and three
  /// markers cannot be checked for an outlier: on the reference plates of spent sets 16-17 (5434
  /// poses) a 3-of-4 pose errs by 1.12 deg / 0.61 mm RMS against 0.52 deg / 0.27 mm for a whole one
  /// (1.2 % beyond 5 deg or 5 mm left out), variance ratios 4.7 / 5.3 that its fit's chi-square
  /// does not show (docs/tracking.md 1). 1: counted as a whole one.
  double partial_variance_scale = 5.0;
  /// Beyond noise_growth_range_mm the `ahat` filter's position sigma (filter.position_sigma_mm:
  /// a pose at that range) grows as (range / noise_growth_range_mm)^noise_growth_exponent: one
  /// marker pixel's range sd grows as range^1.5 (STTAR, docs/simulator.md 10.1) and a marker
  /// covers range^-2 pixels, so a pose's noise along the view ray grows as range^2.5 (rendered:
  /// 0.045 / 0.15 / 0.36 mm RMS at 300 / 500 / 700 mm, most of it along the ray; 0.15 at 470).
  /// Without it, noise at 700 mm looked like a manoeuvre to the filter, which followed it. It
  /// counts in full while the camera stands still and fades as 3 mm/s^2 over the raised process
  /// noise (camera_motion_bandwidth_per_s) when it moves.
  double noise_growth_range_mm = 470.0;
  double noise_growth_exponent = 2.5;  // 0 turns both off
  /// ... and both filters' orientation sigma (filter.rotation_sigma_rad, 0.003 rad) beyond this
  /// range, in full (the world filter's orientation does not follow the camera): the suite's disc
  /// plates, raw, 0.16 deg RMS at 340 mm and 0.5-0.8 deg at 550-650 mm (0.0069 rad per axis at
  /// 600 mm by the law). Near poses then count for more than far ones (docs/tracking.md 1).
  double rotation_noise_growth_range_mm = 430.0;
  int max_missed_frames = 5;  // frames without a pose before the filter and prior are dropped
  void Check() const;         // throws std::invalid_argument naming the bad field
};

/// One tool in one frame. Poses exist only when measured in this frame: never a stale pose.
struct TrackedTool {
  ToolPoseResult measurement;  // status, raw ahat_from_tool, FRE, matched detections, evidence
  /// Filtered pose at this frame's time; nullopt unless the measurement has a pose, the filter is
  /// enabled and the measurement passed the gate.
  std::optional<Rigid3d> filtered_ahat_from_tool;
  bool gated = false;         // the filter rejected this frame's raw pose as an outlier
  bool filter_reset = false;  // the filter (re-)started from this frame's raw pose
  /// With the filtered pose and the world orientation filter: the RMS angle error its orientation
  /// is expected to have (all three axes) [rad], this frame's fit sd (measurement.rotation_sd_rad,
  /// with the filter's inflation for a poor fit or a partial pose) times what the filter left of
  /// one frame's variance. One frame's sd at a (re-)start, shrinking as the filter averages a
  /// still tool; kept about over a gap the tool was held in `world` (docs/tracking.md 1, "A
  /// pose that is still settling").
  std::optional<double> filtered_rotation_sd_rad;
  ToolStatus status() const { return measurement.status; }
};

struct TrackingFrame {
  double timestamp_s = 0.0;
  std::vector<TrackedTool> tools;  // in ToolTracker::tools() order
};

/// Tracks a fixed set of tools over frames (Sec. III-C). Give it detections whose ranges were
/// already corrected by Eq. (2) when an f_rf model is used (tracking does not know correction).
class ToolTracker {
 public:
  /// Throws std::invalid_argument on bad options or a tool that fails ToolGeometry::Check().
  explicit ToolTracker(std::vector<ToolGeometry> tools, const ToolTrackerOptions& options = {});

  /// `world_from_ahat`: the camera pose of this frame when known (world_from_rig * rig_from_ahat).
  /// `dropped`: the frame's dropped blobs (MarkerDetectionResult::dropped), to say why a tool
  /// marker on one was not used. `void_test`: the frame's images, to refuse a pose that puts an
  /// unmatched marker in empty space (EstimateToolPoses).
  TrackingFrame Track(std::span<const DetectedMarker> detections, double timestamp_s,
                      const std::optional<Rigid3d>& world_from_ahat = std::nullopt,
                      std::span<const DroppedBlob> dropped = {},
                      const MarkerVoidTest* void_test = nullptr);
  const std::vector<ToolGeometry>& tools() const { return tools_; }
  void Reset();

 private:
  std::vector<ToolGeometry> tools_;
  std::vector<Eigen::Vector3d> centroid_in_tool_;  // per tool: its markers' centroid
  ToolTrackerOptions options_;
  std::vector<PoseFilter> filters_;                    // ahat_from_tool
  std::vector<WorldOrientationFilter> world_filters_;  // world_from_tool's orientation
  std::vector<WorldPositionFilter> world_positions_;   // the markers' centroid in `world`
  RigJitterEstimate rig_jitter_;                       // one rig pose per frame: shared
  std::vector<std::optional<Rigid3d>> last_pose_;      // last raw pose (prior when unfiltered)
  std::vector<double> last_seen_s_;
  std::vector<int> missed_;
  std::deque<std::pair<double, Rigid3d>> camera_poses_;  // (time, world_from_ahat), newest last
};

}  // namespace tofnav
