// SPDX-License-Identifier: BSD-3-Clause
// Navigator: detection, Eq. (2), tool poses, Eq. (8), the plan and the instrument's guidance.
#include "tofnav/pipeline/navigator.hpp"

#include <cmath>
#include <limits>
#include <utility>

#include "tofnav/core/require.hpp"

namespace tofnav {
namespace {

/// The reference's pose in this frame: filtered when the filter runs (NavigatorOptions::tracking),
/// raw otherwise; none when unmeasured or gated as an outlier.
std::optional<Rigid3d> ReferencePose(const TrackedTool& tool, bool filter_enabled) {
  if (!filter_enabled) return tool.measurement.ahat_from_tool;
  return tool.filtered_ahat_from_tool;
}

std::vector<ToolGeometry> TrackedTools(const NavigationCase& c) {
  std::vector<ToolGeometry> tools{c.reference};
  if (c.instrument) tools.push_back(*c.instrument);
  return tools;
}

// The tracker's options with f_rf's entrance-angle term for disc tools (docs/tracking.md 4).
ToolTrackerOptions WithEntranceGain(ToolTrackerOptions options, const MarkerRangeModel& frf) {
  options.pose.marker_entrance_gain_mm_per_rad = frf.entrance_gain_mm_per_rad;
  return options;
}

}  // namespace

void NavigatorOptions::Check() const {
  markers.Check();
  tracking.Check();
  Require(std::isfinite(stale_after_s) && stale_after_s > 0.0,
          "NavigatorOptions.stale_after_s must be > 0");
  pose_jumps.Check();
  Require(std::isfinite(held_mean_span_s) && held_mean_span_s >= 0.0,
          "NavigatorOptions.held_mean_span_s must be >= 0");
  Require(settled_rotation_sd_rad > 0.0,
          "NavigatorOptions.settled_rotation_sd_rad must be > 0 (infinity: never settling)");
  Require(!instrument_axis_in_tool || instrument_axis_in_tool->norm() > 0.0,
          "NavigatorOptions.instrument_axis_in_tool must be non-zero");
}

const char* ToString(NavigationStatus status) {
  switch (status) {
    case NavigationStatus::kTracking:
      return "TRACKING";
    case NavigationStatus::kHolding:
      return "HOLDING";
    case NavigationStatus::kReferenceLost:
      return "REFERENCE_LOST";
    case NavigationStatus::kNoWorldPose:
      return "NO_WORLD_POSE";
    case NavigationStatus::kNoStream:
      return "NO_STREAM";
  }
  return "?";
}

Navigator::Navigator(AhatCamera camera, NavigationCase navigation_case,
                     const NavigatorOptions& options)
    : camera_(std::move(camera)),
      case_(std::move(navigation_case)),
      options_(options),
      tracker_(TrackedTools(case_), WithEntranceGain(options.tracking, case_.marker_range)),
      reference_guard_(options.pose_jumps) {
  options_.Check();
  for (const Trajectory& t : case_.plan) {
    Require((t.target_lps_mm - t.entry_lps_mm).norm() > 0.0,
            "trajectory '" + t.name + "': entry and target coincide");
  }
  if (case_.instrument) {
    const ToolGeometry& tool = *case_.instrument;
    Require(tool.tip_in_tool.has_value(), "instrument '" + tool.name + "' has no tip");
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& m : tool.markers_in_tool) centroid += m;
    centroid /= static_cast<double>(tool.markers_in_tool.size());
    instrument_axis_in_tool_ =
        options_.instrument_axis_in_tool.value_or(*tool.tip_in_tool - centroid);
    Require(instrument_axis_in_tool_.norm() > 0.0,
            "instrument '" + tool.name + "': tip at the markers' centroid, give the axis");
    instrument_axis_in_tool_.normalize();
  }
}

void Navigator::SelectTrajectory(int index) {
  Require(index >= 0 && static_cast<std::size_t>(index) < case_.plan.size(),
          "SelectTrajectory: index out of range");
  active_trajectory_ = index;
}

NavigationState Navigator::Process(const AhatFrame& frame) {  // Sec. III-C
  const double timestamp_s = frame.timestamp_s();
  const MarkerDetectionResult detected = LocateMarkers(frame, camera_, options_.markers);
  // Eq. (2): marker ranges corrected by f_rf before the sphere radius is added.
  const std::vector<DetectedMarker> corrected =
      CorrectMarkerRanges(detected.markers, case_.marker_range);
  std::optional<Rigid3d> world_from_ahat;
  if (frame.world_from_rig) world_from_ahat = *frame.world_from_rig * camera_.rig_from_ahat();
  const MarkerVoidTest void_test(frame, camera_, detected.ab_threshold);
  const TrackingFrame tracked = tracker_.Track(corrected, timestamp_s, world_from_ahat,
                                               detected.dropped, &void_test);  // ahat_from_tool
  return Place(timestamp_s, tracked, frame.world_from_rig, static_cast<int>(corrected.size()));
}

NavigationState Navigator::Place(double timestamp_s, const TrackingFrame& tracked,
                                 const std::optional<Rigid3d>& world_from_rig,
                                 int detected_markers) {
  NavigationState state;
  state.timestamp_s = timestamp_s;
  state.detected_markers = detected_markers;
  state.world_from_rig = world_from_rig;
  state.active_trajectory = active_trajectory_;
  Require(!tracked.tools.empty(), "Navigator::Place: no reference in the tracking frame");
  const TrackedTool& reference = tracked.tools.front();
  state.reference_status = reference.status();
  state.reference_marker_use = reference.measurement.marker_use;
  for (const TrackedTool& t : tracked.tools) {
    state.poses_refused_void += t.measurement.candidates_refused_void;
  }
  state.ahat_from_tool = ReferencePose(reference, options_.tracking.filter_enabled);
  bool fresh = false;
  if (state.ahat_from_tool && world_from_rig) {
    const Rigid3d world_from_tool =
        *world_from_rig * camera_.rig_from_ahat() * *state.ahat_from_tool;
    if (options_.check_pose_jumps) {
      state.reference_pose_check = reference_guard_.Judge(world_from_tool, timestamp_s);
      state.reference_pose_jump = state.reference_pose_check.status == PoseConsistency::kJump;
    }
    if (state.reference_pose_jump) {
      state.ahat_from_tool.reset();  // as if unseen: HOLDING on the accepted poses
    } else {
      // Eq. (8): world_from_image = world_from_rig * rig_from_ahat * ahat_from_tool *
      // tool_from_image
      held_world_from_image_ = world_from_tool * case_.tool_from_image;
      held_rotation_sd_rad_ = reference.filtered_rotation_sd_rad;
      reference_seen_s_ = timestamp_s;
      fresh = true;
    }
  }
  state.reference_age_s = reference_seen_s_ ? timestamp_s - *reference_seen_s_
                                            : std::numeric_limits<double>::infinity();
  const bool current = state.reference_age_s <= options_.stale_after_s;
  if (!current) held_world_from_image_.reset();  // never re-used as if it were current
  if (current && !fresh && options_.check_pose_jumps && options_.held_mean_span_s > 0.0) {
    // Held: the mean of the last accepted world poses, not the last one alone.
    if (const auto mean = reference_guard_.Mean(*reference_seen_s_, options_.held_mean_span_s)) {
      held_world_from_image_ = *mean * case_.tool_from_image;
    }
  }
  state.world_from_image = held_world_from_image_;
  if (state.world_from_image) {
    state.reference_rotation_sd_rad = held_rotation_sd_rad_;
    state.reference_settling = IsSettling(held_rotation_sd_rad_, options_.settled_rotation_sd_rad);
  }
  if (state.ahat_from_tool) {
    state.status = world_from_rig ? NavigationStatus::kTracking : NavigationStatus::kNoWorldPose;
  } else {
    state.status = current ? NavigationStatus::kHolding : NavigationStatus::kReferenceLost;
  }
  if (state.world_from_image) {
    for (const Trajectory& t : case_.plan) {
      state.plan.push_back(
          {*state.world_from_image * t.entry_lps_mm, *state.world_from_image * t.target_lps_mm,
           case_.tool_from_image * t.entry_lps_mm, case_.tool_from_image * t.target_lps_mm});
    }
  }
  if (case_.instrument && tracked.tools.size() > 1) PlaceInstrument(state, tracked.tools[1]);
  return state;
}

void Navigator::PlaceInstrument(NavigationState& state, const TrackedTool& instrument) const {
  state.instrument_status = instrument.status();
  state.instrument_marker_use = instrument.measurement.marker_use;
  state.ahat_from_instrument = instrument.measurement.ahat_from_tool;  // raw (NavigatorOptions)
  if (!state.ahat_from_instrument) return;
  if (state.ahat_from_tool) {
    state.tool_from_instrument = state.ahat_from_tool->Inverse() * *state.ahat_from_instrument;
  }
  // In `world`, so the held reference pose still guides while the hand hides the headframe.
  if (!state.world_from_rig || state.plan.empty()) return;
  const Rigid3d world_from_instrument =
      *state.world_from_rig * camera_.rig_from_ahat() * *state.ahat_from_instrument;
  state.tip_in_world = world_from_instrument * *case_.instrument->tip_in_tool;
  const Eigen::Vector3d axis_in_world = world_from_instrument.rotation * instrument_axis_in_tool_;
  state.instrument_axis_in_world = axis_in_world;
  const PlacedTrajectory& t = state.plan[static_cast<std::size_t>(active_trajectory_)];
  state.guidance =
      ComputeGuidance(*state.tip_in_world, axis_in_world, t.entry_in_world, t.target_in_world);
}

}  // namespace tofnav
