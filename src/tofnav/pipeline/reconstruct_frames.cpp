// SPDX-License-Identifier: BSD-3-Clause
// Internal to ReconstructSurface: the tracking pass and the temporal pose check.
#include "tofnav/pipeline/reconstruct_frames.hpp"

#include <algorithm>
#include <chrono>

#include "tofnav/core/parallel_for.hpp"
#include "tofnav/tracking/pose_consistency.hpp"
#include "tofnav/tracking/tool_tracker.hpp"

namespace tofnav {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

constexpr std::size_t kBatchFrames = 16;  // frames whose markers are located in parallel

}  // namespace

std::vector<TrackedFrame> TrackFrames(const AhatRecording& recording, const AhatCamera& camera,
                                      const ToolGeometry& tool, const ReconstructOptions& options,
                                      const std::vector<std::size_t>& frames,
                                      ReconstructResult& result,
                                      const std::function<void(std::size_t)>& progress) {
  ToolTrackerOptions tracker_options;
  tracker_options.pose = options.pose;
  // Per-frame measured poses: a filter lags (docs/reconstruction.md 6.1).
  tracker_options.filter_enabled = false;
  ToolTracker tracker({tool}, tracker_options);
  std::vector<TrackedFrame> out(frames.size());
  std::vector<AhatFrame> batch;
  std::vector<std::vector<DetectedMarker>> markers;
  for (std::size_t b = 0; b < frames.size(); b += kBatchFrames) {
    const std::size_t count = std::min(kBatchFrames, frames.size() - b);
    Clock::time_point t = Clock::now();
    batch.resize(count);
    markers.resize(count);
    for (std::size_t k = 0; k < count; ++k) batch[k] = recording.ReadFrame(frames[b + k]);
    result.read_s += Seconds(t);
    t = Clock::now();
    ParallelFor(0, static_cast<std::int64_t>(count), [&](std::int64_t i) {
      const auto k = static_cast<std::size_t>(i);
      MarkerDetectionResult detection = LocateMarkers(batch[k], camera, options.detection);
      out[b + k].ab_threshold = detection.ab_threshold;
      markers[k] = options.marker_error.empty()
                       ? std::move(detection.markers)
                       : CorrectMarkerRanges(std::move(detection.markers), options.marker_error);
    });
    result.prepare_s += Seconds(t);
    t = Clock::now();
    for (std::size_t k = 0; k < count; ++k) {
      TrackedFrame& f = out[b + k];
      f.index = frames[b + k];
      f.timestamp_s = batch[k].timestamp_s();
      f.world_from_rig = batch[k].world_from_rig;
      const TrackedTool tracked = tracker.Track(markers[k], f.timestamp_s).tools[0];
      f.status = tracked.status();
      const bool posed =
          f.status == ToolStatus::kOk ||
          (options.accept_partially_occluded && f.status == ToolStatus::kPartiallyOccluded);
      if (posed) f.ahat_from_tool = tracked.measurement.ahat_from_tool;
      if (progress) progress(b + k + 1);
    }
    result.track_s += Seconds(t);
  }
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

}  // namespace tofnav
