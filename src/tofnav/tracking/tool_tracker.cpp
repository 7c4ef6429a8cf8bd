// SPDX-License-Identifier: BSD-3-Clause
// ToolTracker: EstimateToolPoses with a temporal prior, then one PoseFilter per tool.
#include "tofnav/tracking/tool_tracker.hpp"

#include <utility>

#include "tofnav/core/require.hpp"

namespace tofnav {

void ToolTrackerOptions::Check() const {
  pose.Check();
  filter.Check();
  Require(max_missed_frames >= 1, "ToolTrackerOptions::max_missed_frames must be >= 1");
}

ToolTracker::ToolTracker(std::vector<ToolGeometry> tools, const ToolTrackerOptions& options)
    : tools_(std::move(tools)), options_(options) {
  options.Check();
  for (const ToolGeometry& tool : tools_) tool.Check();
  filters_.assign(tools_.size(), PoseFilter(options.filter));
  world_filters_.assign(tools_.size(), PoseFilter(options.filter));
  Reset();
}

void ToolTracker::Reset() {
  for (PoseFilter& f : filters_) f.Reset();
  for (PoseFilter& f : world_filters_) f.Reset();
  last_pose_.assign(tools_.size(), std::nullopt);
  last_seen_s_.assign(tools_.size(), 0.0);
  missed_.assign(tools_.size(), 0);
}

TrackingFrame ToolTracker::Track(std::span<const DetectedMarker> detections, double timestamp_s,
                                 const std::optional<Rigid3d>& world_from_ahat) {
  const bool in_world = options_.filter_enabled && options_.rotation_in_world && world_from_ahat;
  std::vector<std::optional<Rigid3d>> prior(tools_.size());
  for (std::size_t t = 0; t < tools_.size(); ++t) {
    if (options_.filter_enabled) {
      prior[t] = filters_[t].Predict(timestamp_s);
    } else if (last_pose_[t] && timestamp_s - last_seen_s_[t] <= options_.filter.max_gap_s) {
      prior[t] = last_pose_[t];
    }
  }
  TrackingFrame frame;
  frame.timestamp_s = timestamp_s;
  std::vector<ToolPoseResult> poses = EstimateToolPoses(detections, tools_, prior, options_.pose);
  for (std::size_t t = 0; t < tools_.size(); ++t) {
    TrackedTool tracked;
    tracked.measurement = std::move(poses[t]);
    const std::optional<Rigid3d>& raw = tracked.measurement.ahat_from_tool;
    if (!raw) {
      if (++missed_[t] >= options_.max_missed_frames) {  // a loss: drop the prior and the state
        filters_[t].Reset();
        world_filters_[t].Reset();
        last_pose_[t].reset();
      }
      frame.tools.push_back(std::move(tracked));
      continue;
    }
    missed_[t] = 0;
    last_pose_[t] = raw;
    last_seen_s_[t] = timestamp_s;
    if (options_.filter_enabled) {
      const PoseFilterUpdate update = filters_[t].Update(*raw, timestamp_s);
      tracked.gated = update.gated;
      tracked.filter_reset = update.reset;
      if (!update.gated) tracked.filtered_ahat_from_tool = update.filtered;
      if (!in_world) {
        world_filters_[t].Reset();
      } else {
        const PoseFilterUpdate world =
            world_filters_[t].Update(*world_from_ahat * *raw, timestamp_s);
        if (!update.gated && !world.gated) {
          tracked.filtered_ahat_from_tool->rotation =
              (world_from_ahat->Inverse() * world.filtered).rotation;
        }
      }
    }
    frame.tools.push_back(std::move(tracked));
  }
  return frame;
}

}  // namespace tofnav
