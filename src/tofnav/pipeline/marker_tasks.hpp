// SPDX-License-Identifier: BSD-3-Clause
// Shared by track, fit-marker-error and demo: tool poses of a recording, stage range errors.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "tofnav/casefile/tool_poses_io.hpp"
#include "tofnav/correction/marker_range_model.hpp"
#include "tofnav/pipeline/marker_frames.hpp"
#include "tofnav/tracking/linear_stage.hpp"
#include "tofnav/tracking/tool_tracker.hpp"

namespace tofnav {

using Progress = std::function<void(std::size_t, std::size_t)>;

/// Markers of one tool left out of its poses over a recording (docs/tracking.md section 6).
struct ToolMarkerDrops {
  std::int64_t posed_frames = 0;
  std::int64_t frames_with_drops = 0;  // posed frames with a marker dropped (not just unseen)
  std::int64_t unchecked_frames = 0;   // posed from markers too few to check for an outlier
  /// Frames in which a candidate pose was refused: it put an unmatched marker where the images
  /// show empty space (MarkerVoidTest), and candidates refused in all.
  std::int64_t frames_with_void_refusals = 0;
  std::int64_t void_refusals = 0;
  /// Per tool marker: posed frames in which it was not kUsed, by MarkerUse.
  std::vector<std::map<MarkerUse, std::int64_t>> per_marker;
};

/// What TrackTools left out, per tool, and the blobs detection dropped, by reason (all frames).
struct TrackingDrops {
  std::vector<ToolMarkerDrops> tools;
  std::map<BlobDropReason, std::int64_t> blobs;
};

/// One record per frame and tool (docs/tracking.md section 3): markers detected, f_rf applied to
/// their ranges when `marker_range` is not empty, tracked by one ToolTracker. Counts the markers
/// left out into `drops` when given.
std::vector<ToolPoseRecord> TrackTools(const MarkerSource& source,
                                       const MarkerDetectionOptions& detection,
                                       const std::vector<ToolGeometry>& tools,
                                       const ToolTrackerOptions& options,
                                       const MarkerRangeModel& marker_range,
                                       const Progress& progress, TrackingDrops* drops = nullptr);

/// One stage run of a recording (split where the structure jumps).
struct StageRun {
  std::size_t run = 0;
  std::size_t frames = 0;
  int frames_used = 0;
  std::optional<double> speed_mm_s, line_rms_mm;
  std::size_t samples = 0;
  std::string dropped;  // why the run's samples were not used; empty when used
};

struct StageSamples {
  std::vector<MarkerRangeSample> samples;
  int frames_used = 0;
  std::vector<StageRun> runs;
};

struct StageSampleOptions {
  double split_jump_mm = 20.0;  // a larger structure jump between frames starts a new run
  /// The stage's commanded speed: each run's reference line moves at it, and runs whose fitted
  /// speed is more than speed_tolerance off are dropped.
  std::optional<double> speed_mm_s;
  double speed_tolerance = 0.1;
  StageRangeErrorOptions stage;
};

/// Sec. III-A.1 on one recording: detections per frame, runs split, each run's range errors
/// measured (MeasureMarkerRangeErrors); runs that fail or miss the nominal speed are dropped.
StageSamples CollectStageSamples(const MarkerSource& source,
                                 const MarkerDetectionOptions& detection,
                                 const ToolGeometry& structure, const StageSampleOptions& options,
                                 const Progress& progress);

}  // namespace tofnav
