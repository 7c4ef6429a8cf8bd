// SPDX-License-Identifier: BSD-3-Clause
// The intra-operative orchestrator (Sec. III-C): per frame tracking, Eq. (8), plan and guidance.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "tofnav/correction/marker_range_model.hpp"
#include "tofnav/imaging/trajectory.hpp"
#include "tofnav/markers/marker_detection.hpp"
#include "tofnav/pipeline/guidance.hpp"
#include "tofnav/sensor/ahat_camera.hpp"
#include "tofnav/sensor/ahat_frame.hpp"
#include "tofnav/tracking/pose_jump_guard.hpp"
#include "tofnav/tracking/settling.hpp"
#include "tofnav/tracking/tool_tracker.hpp"

namespace tofnav {

struct NavigatorOptions {
  MarkerDetectionOptions markers;
  /// The reference's pose is filtered (ToolTracker, about its markers' centroid): its orientation
  /// in `world`, where the headframe stands still while the head-worn camera turns, so the
  /// per-frame tilt noise of its plates, times the lever arm to the plan, averages out
  /// (docs/navigation.md 1). The `ahat` filter's position gate is off (gate_floor_mm infinite):
  /// there the headframe moves with every head motion and the gate refused good poses
  /// (evd-usecase: 220 of 240 frames tracked with it, 231 without); the pose jump guard below
  /// judges the world pose instead. The instrument's pose stays raw: it moves in `world`, where
  /// the orientation filter would hold it.
  ToolTrackerOptions tracking{.filter = {.gate_floor_mm = std::numeric_limits<double>::infinity()}};
  /// The reference tool unseen for longer than this [s]: its last pose is no longer current.
  double stale_after_s = 0.1;
  /// The headframe's world pose (world_from_rig * rig_from_ahat * ahat_from_tool) checked against
  /// its last accepted poses: a jump is left out as if the reference were unseen (HOLDING).
  bool check_pose_jumps = true;
  PoseJumpGuardOptions pose_jumps;
  /// While HOLDING, world_from_image is the mean of the accepted world poses of this last span
  /// [s] (5 frames at 45 Hz): the held picture does not keep one frame's noise. While TRACKING it
  /// is this frame's pose, so that the instrument's guidance (same frame, same head pose) is
  /// free of the head tracking's jitter.
  double held_mean_span_s = 0.1;
  /// The reference's pose is SETTLING while its filtered orientation's expected RMS error
  /// (TrackedTool::filtered_rotation_sd_rad) exceeds this [rad]: 0.35 deg, the orientation the
  /// suite holds a plate's tracking to. A plate's first track of a session starts from one
  /// frame's fit (a far plate's 0.5 deg) and is averaged to this in a few frames; a plate back
  /// from a gap starts from its orientation held in the world (docs/navigation.md, "A reference
  /// that is still settling"). Infinity turns it off.
  double settled_rotation_sd_rad = kSettledRotationSdRad;
  /// Instrument axis in its own frame (towards the tip); nullopt: from the markers' centroid to
  /// the tip (a drill whose marker array sits on its shaft axis).
  std::optional<Eigen::Vector3d> instrument_axis_in_tool;
  void Check() const;  // throws PreconditionError naming the bad field
};

/// The constant inputs of a navigated case.
struct NavigationCase {
  ToolGeometry reference;                  // the headframe tool, frame `tool`
  std::optional<ToolGeometry> instrument;  // needs tip_in_tool
  MarkerRangeModel marker_range;           // f_rf (Eq. 1); empty: no correction
  Rigid3d tool_from_image;                 // the registration (Sec. III-B)
  std::vector<Trajectory> plan;            // in `image`
};

enum class NavigationStatus {
  kTracking,       // reference measured in this frame, world pose known
  kHolding,        // reference unseen for <= stale_after_s: the last world_from_image is kept
  kReferenceLost,  // reference unseen for longer (or never seen): no current world_from_image
  kNoWorldPose,    // reference measured, but the frame has no world_from_rig (locator failed)
  kNoStream,       // the headset link is down: no frames (set by stream/, never by Process)
};
const char* ToString(NavigationStatus status);

/// A planned trajectory placed by Eq. (8).
struct PlacedTrajectory {
  Eigen::Vector3d entry_in_world, target_in_world;
  Eigen::Vector3d entry_in_tool, target_in_tool;
};

/// What the Navigator knows after one frame. Poses are of this frame unless said otherwise.
struct NavigationState {
  double timestamp_s = 0.0;
  NavigationStatus status = NavigationStatus::kReferenceLost;
  ToolStatus reference_status = ToolStatus::kOutOfView;  // this frame's measurement
  double reference_age_s = 0.0;  // since the reference was last measured (infinity: never)
  /// With world_from_image: the expected RMS angle error of the reference orientation it was
  /// placed with (its last measured frame's; TrackedTool::filtered_rotation_sd_rad), and SETTLING:
  /// that error is above NavigatorOptions::settled_rotation_sd_rad.
  std::optional<double> reference_rotation_sd_rad;
  bool reference_settling = false;
  double stream_down_s = 0.0;  // kNoStream: since the last frame arrived
  /// Set by stream/ (RunNavigationSession): frames per second received over the last second, and
  /// LOW_RATE: every frame interval has been longer than 1/15 s for over 1 s (FrameRateMonitor).
  double received_rate_hz = 0.0;
  bool low_rate = false;
  int detected_markers = 0;
  /// The reference was measured, but its world pose jumped from its recent ones: left out
  /// (ahat_from_tool empty), and the pose check's deviation.
  bool reference_pose_jump = false;
  PoseConsistencyResult reference_pose_check;
  std::vector<MarkerUse> reference_marker_use;   // per reference marker: in the pose, or why not
  std::vector<MarkerUse> instrument_marker_use;  // the same for the instrument
  /// Candidate poses of the reference and the instrument refused this frame: each put a marker
  /// no blob matched where the images show empty space (MarkerVoidTest, docs/tracking.md 6).
  int poses_refused_void = 0;
  std::optional<Rigid3d> ahat_from_tool;    // reference, measured in this frame (filtered)
  std::optional<Rigid3d> world_from_rig;    // this frame's head pose
  std::optional<Rigid3d> world_from_image;  // Eq. (8): kTracking (current) or kHolding (held)
  std::vector<PlacedTrajectory> plan;       // one per NavigationCase::plan when world_from_image
  std::optional<ToolStatus> instrument_status;  // with an instrument only
  std::optional<Rigid3d> ahat_from_instrument;  // measured in this frame
  std::optional<Rigid3d> tool_from_instrument;  // both tools measured in this frame
  std::optional<Eigen::Vector3d> tip_in_world;
  std::optional<Eigen::Vector3d> instrument_axis_in_world;  // unit, towards the tip
  int active_trajectory = 0;
  std::optional<Guidance> guidance;  // instrument vs the active trajectory, in `world`
};

/// The one stateful orchestrator of phase 3: camera, tools, f_rf, tool_from_image, tracker state
/// and the last world pose. Single-threaded; one per tracked stream.
class Navigator {
 public:
  /// Throws PreconditionError on bad options, an instrument without a tip, or an empty plan
  /// trajectory; std::invalid_argument from the tools' Check().
  Navigator(AhatCamera camera, NavigationCase navigation_case,
            const NavigatorOptions& options = {});

  /// Sec. III-C for one frame; frames must come in time order.
  NavigationState Process(const AhatFrame& frame);
  /// Eq. (8) and the plan from given poses (no detection): the tail of Process.
  NavigationState Place(double timestamp_s, const TrackingFrame& tracked,
                        const std::optional<Rigid3d>& world_from_rig, int detected_markers);
  /// Frames whose reference pose was left out as a jump, and restarts of the pose check.
  int reference_pose_jumps() const { return reference_guard_.jumps(); }
  /// Selects the trajectory guidance refers to; PreconditionError when out of range.
  void SelectTrajectory(int index);
  const NavigationCase& navigation_case() const { return case_; }
  const AhatCamera& camera() const { return camera_; }

 private:
  void PlaceInstrument(NavigationState& state, const TrackedTool& instrument) const;

  AhatCamera camera_;
  NavigationCase case_;
  NavigatorOptions options_;
  ToolTracker tracker_;
  Eigen::Vector3d instrument_axis_in_tool_ = Eigen::Vector3d::UnitZ();
  int active_trajectory_ = 0;
  std::optional<double> reference_seen_s_;
  std::optional<Rigid3d> held_world_from_image_;
  std::optional<double> held_rotation_sd_rad_;  // of the pose held_world_from_image_ came from
  PoseJumpGuard reference_guard_;
};

}  // namespace tofnav
