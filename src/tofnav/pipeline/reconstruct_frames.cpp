// SPDX-License-Identifier: BSD-3-Clause
// Internal to ReconstructSurface: the tracking pass and the temporal pose check.
#include "tofnav/pipeline/reconstruct_frames.hpp"

#include <algorithm>

#include "tofnav/core/frame_batches.hpp"
#include "tofnav/tracking/pose_consistency.hpp"
#include "tofnav/tracking/rotation_smoothing.hpp"
#include "tofnav/tracking/tool_tracker.hpp"

namespace tofnav {
namespace {

constexpr std::size_t kLocateBatchFrames = 16;  // frames whose markers are located in parallel

}  // namespace

std::vector<TrackedFrame> TrackFrames(const AhatRecording& recording, const AhatCamera& camera,
                                      const ToolGeometry& tool, const ReconstructOptions& options,
                                      const std::vector<std::size_t>& frames,
                                      ReconstructResult& result,
                                      const std::function<void(std::size_t)>& progress) {
  ToolTrackerOptions tracker_options;
  tracker_options.pose = options.pose;
  // f_rf's entrance-angle term for disc tools (docs/tracking.md 4).
  tracker_options.pose.marker_entrance_gain_mm_per_rad =
      options.marker_error.entrance_gain_mm_per_rad;
  // Per-frame measured poses: a filter lags (docs/reconstruction.md 6.1).
  tracker_options.filter_enabled = false;
  ToolTracker tracker({tool}, tracker_options);
  std::vector<TrackedFrame> out(frames.size());
  struct Item {
    AhatFrame frame;
    std::vector<DetectedMarker> markers;
  };
  BatchTimes times;
  ForEachInBatches<Item>(
      frames.size(), kLocateBatchFrames,
      [&](std::size_t p) {
        return Item{recording.ReadFrame(frames[p]), {}};
      },
      [&](Item& item, std::size_t p) {
        MarkerDetectionResult detection = LocateMarkers(item.frame, camera, options.detection);
        out[p].ab_threshold = detection.ab_threshold;
        item.markers =
            options.marker_error.empty()
                ? std::move(detection.markers)
                : CorrectMarkerRanges(std::move(detection.markers), options.marker_error);
      },
      [&](Item& item, std::size_t p) {
        TrackedFrame& f = out[p];
        f.index = frames[p];
        f.timestamp_s = item.frame.timestamp_s();
        f.world_from_rig = item.frame.world_from_rig;
        const MarkerVoidTest void_test(item.frame, camera, f.ab_threshold);
        const TrackedTool tracked =
            tracker.Track(item.markers, f.timestamp_s, std::nullopt, {}, &void_test).tools[0];
        f.status = tracked.status();
        const bool posed =
            f.status == ToolStatus::kOk ||
            (options.accept_partially_occluded && f.status == ToolStatus::kPartiallyOccluded);
        if (posed) f.ahat_from_tool = tracked.measurement.ahat_from_tool;
        if (progress) progress(p + 1);
      },
      &times);
  result.read_s += times.read_s;
  result.prepare_s += times.prepare_s;
  result.track_s += times.consume_s;
  return out;
}

std::size_t FlagPoseJumps(const AhatCamera& camera, const ReconstructOptions& options,
                          std::vector<TrackedFrame>& frames) {
  std::vector<std::optional<Rigid3d>> world_from_tool(frames.size());
  std::vector<double> time_s(frames.size());
  std::vector<double> steps;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const TrackedFrame& f = frames[i];
    time_s[i] = f.timestamp_s;
    if (i > 0) steps.push_back(f.timestamp_s - frames[i - 1].timestamp_s);
    if (f.ahat_from_tool && f.world_from_rig) {
      world_from_tool[i] = *f.world_from_rig * camera.rig_from_ahat() * *f.ahat_from_tool;
    }
  }
  PoseConsistencyOptions consistency = options.pose_consistency;
  if (!steps.empty()) {  // hold min_neighbours frames at the frames' own median interval
    std::nth_element(steps.begin(), steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 2),
                     steps.end());
    const double interval_s = std::max(steps[steps.size() / 2], 0.0);
    consistency.window_s =
        std::max(consistency.window_s,
                 interval_s * (0.5 * static_cast<double>(consistency.min_neighbours) + 1.0));
  }
  std::size_t judged = 0;
  const std::vector<PoseConsistencyResult> checked =
      CheckPoseConsistency(world_from_tool, time_s, consistency);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    if (checked[i].status != PoseConsistency::kUnchecked) ++judged;
    frames[i].pose_jump = checked[i].status == PoseConsistency::kJump;
  }
  return judged;
}

std::size_t SmoothToolRotations(const AhatCamera& camera, const ReconstructOptions& options,
                                std::vector<TrackedFrame>& frames) {
  std::vector<std::optional<Rigid3d>> ahat_from_tool(frames.size()), world_from_ahat(frames.size());
  std::vector<double> time_s(frames.size());
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const TrackedFrame& f = frames[i];
    time_s[i] = f.timestamp_s;
    ahat_from_tool[i] = f.ahat_from_tool;
    if (f.world_from_rig && !f.pose_jump)
      world_from_ahat[i] = *f.world_from_rig * camera.rig_from_ahat();
  }
  const std::size_t count =
      SmoothAhatRotations(ahat_from_tool, world_from_ahat, time_s, options.rotation_smoothing);
  for (std::size_t i = 0; i < frames.size(); ++i) frames[i].ahat_from_tool = ahat_from_tool[i];
  return count;
}

}  // namespace tofnav
