// SPDX-License-Identifier: BSD-3-Clause
// Internal to ReconstructSurface: the tracking pass over the frames and the temporal pose check.
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <vector>

#include "tofnav/pipeline/reconstruct.hpp"

namespace tofnav {

/// One considered frame after the tracking pass.
struct TrackedFrame {
  std::size_t index = 0;  // in the recording
  ToolStatus status = ToolStatus::kTooFewMarkers;
  std::optional<Rigid3d> ahat_from_tool;  // set when the frame is posed (options' statuses)
  double ab_threshold = 0.0;              // the marker detection's AB threshold
  double timestamp_s = 0.0;
  std::optional<Rigid3d> world_from_rig;  // the headset's pose, when the locator had one
  bool pose_jump = false;                 // left out by the temporal check
};

/// Markers (f_rf-corrected when given) and the tool's unfiltered pose for every frame of
/// `frames`, in order; adds the reading, marker and tracking times to `result`.
std::vector<TrackedFrame> TrackFrames(const AhatRecording& recording, const AhatCamera& camera,
                                      const ToolGeometry& tool, const ReconstructOptions& options,
                                      const std::vector<std::size_t>& frames,
                                      ReconstructResult& result,
                                      const std::function<void(std::size_t)>& progress);

/// The temporal check (tracking/pose_consistency.hpp) of the posed frames' world_from_tool =
/// world_from_rig * rig_from_ahat * ahat_from_tool (frames without world_from_rig are not
/// judged): sets pose_jump. The window is widened to hold min_neighbours frames when frames are
/// skipped (frame_step). Returns the number of frames judged.
std::size_t FlagPoseJumps(const AhatCamera& camera, const ReconstructOptions& options,
                          std::vector<TrackedFrame>& frames);

/// The posed, unjumped frames' tool orientations replaced by SmoothWorldRotations of their
/// world_from_tool (tracking/rotation_smoothing.hpp) mapped back through the frame's own
/// world_from_ahat; the position stays as measured. Returns the number of frames smoothed.
std::size_t SmoothToolRotations(const AhatCamera& camera, const ReconstructOptions& options,
                                std::vector<TrackedFrame>& frames);

}  // namespace tofnav
