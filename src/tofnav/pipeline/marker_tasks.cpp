// SPDX-License-Identifier: BSD-3-Clause
// Tool poses of a recording and stage range errors, shared by the marker commands and the demo.
#include "tofnav/pipeline/marker_tasks.hpp"

#include <cmath>
#include <stdexcept>

#include "tofnav/core/units.hpp"
#include "tofnav/markers/marker_centre.hpp"

namespace tofnav {
namespace {

ToolPoseRecord Record(std::size_t index, const AhatFrame& frame, const ToolGeometry& tool,
                      const TrackedTool& tracked, const Rigid3d& rig_from_ahat) {
  ToolPoseRecord r;
  r.frame = static_cast<std::int64_t>(index);
  r.host_ticks = frame.host_ticks;
  r.time_s = frame.timestamp_s();
  r.tool = tool.name;
  r.status = tracked.status();
  r.marker_count = static_cast<int>(tool.markers_in_tool.size());
  r.ahat_from_tool = tracked.measurement.ahat_from_tool;
  if (r.ahat_from_tool) {
    r.markers_used = tracked.measurement.used_markers;
    r.fre_mm = tracked.measurement.fre_rms_mm;
    r.rotation_sd_deg = tracked.measurement.rotation_sd_rad * kRadToDeg;
    r.position_sd_mm = tracked.measurement.position_sd_mm;
  }
  r.filtered_ahat_from_tool = tracked.filtered_ahat_from_tool;
  if (tracked.filtered_rotation_sd_rad) {
    r.filtered_rotation_sd_deg = *tracked.filtered_rotation_sd_rad * kRadToDeg;
  }
  r.gated = tracked.gated;
  if (r.best_ahat_from_tool() && frame.world_from_rig) {
    r.world_from_tool = *frame.world_from_rig * rig_from_ahat * *r.best_ahat_from_tool();
  }
  return r;
}

// Adds one frame's marker uses of a tool to its tally.
void Tally(const TrackedTool& tracked, ToolMarkerDrops& drops) {
  const ToolPoseResult& m = tracked.measurement;
  if (m.candidates_refused_void > 0) {
    ++drops.frames_with_void_refusals;
    drops.void_refusals += m.candidates_refused_void;
  }
  if (!m.ahat_from_tool) return;
  ++drops.posed_frames;
  if (!m.outliers_checked) ++drops.unchecked_frames;
  drops.per_marker.resize(m.marker_use.size());
  bool dropped = false;
  for (std::size_t k = 0; k < m.marker_use.size(); ++k) {
    const MarkerUse use = m.marker_use[k];
    if (use == MarkerUse::kUsed) continue;
    ++drops.per_marker[k][use];
    dropped = dropped || (!InPose(use) && use != MarkerUse::kUnseen);
  }
  if (dropped) ++drops.frames_with_drops;
}

std::optional<Rigid3d> WorldFromAhat(const AhatFrame& frame, const AhatCamera& camera) {
  if (!frame.world_from_rig) return std::nullopt;
  return *frame.world_from_rig * camera.rig_from_ahat();
}

// Splits a recording into stage runs where the structure jumps (a new run starts elsewhere).
std::vector<std::vector<StageFrame>> SplitRuns(std::vector<StageFrame> frames,
                                               const ToolGeometry& structure, double jump_mm) {
  std::vector<std::vector<StageFrame>> runs(1);
  std::optional<Eigen::Vector3d> last;
  for (StageFrame& f : frames) {
    const Points3d centres = MarkerCentres(f.markers, structure.SurfaceToCentreMm());
    const ToolPoseResult pose = EstimateToolPose(centres, structure);
    if (pose.ahat_from_tool) {
      if (last && (pose.ahat_from_tool->translation - *last).norm() > jump_mm &&
          !runs.back().empty()) {
        runs.emplace_back();
      }
      last = pose.ahat_from_tool->translation;
    }
    runs.back().push_back(std::move(f));
  }
  return runs;
}

}  // namespace

std::vector<ToolPoseRecord> TrackTools(const MarkerSource& source,
                                       const MarkerDetectionOptions& detection,
                                       const std::vector<ToolGeometry>& tools,
                                       const ToolTrackerOptions& options,
                                       const MarkerRangeModel& marker_range,
                                       const Progress& progress, TrackingDrops* drops) {
  ToolTrackerOptions tracking = options;  // f_rf's entrance-angle term (docs/tracking.md 4)
  tracking.pose.marker_entrance_gain_mm_per_rad = marker_range.entrance_gain_mm_per_rad;
  ToolTracker tracker(tools, tracking);
  std::vector<ToolPoseRecord> records;
  if (drops) drops->tools.assign(tools.size(), {});
  ForEachFrameDetections(
      source, detection,
      [&](std::size_t index, const AhatFrame& frame, MarkerDetectionResult& detected) {
        std::vector<DetectedMarker>& markers = detected.markers;
        if (!marker_range.empty()) markers = CorrectMarkerRanges(std::move(markers), marker_range);
        const MarkerVoidTest void_test(frame, *source.camera, detected.ab_threshold);
        const TrackingFrame tracked =
            tracker.Track(markers, frame.timestamp_s(), WorldFromAhat(frame, *source.camera),
                          detected.dropped, &void_test);
        if (drops) {
          for (const DroppedBlob& b : detected.dropped) ++drops->blobs[b.reason];
          for (std::size_t t = 0; t < tools.size(); ++t) Tally(tracked.tools[t], drops->tools[t]);
        }
        for (std::size_t t = 0; t < tools.size(); ++t) {
          records.push_back(
              Record(index, frame, tools[t], tracked.tools[t], source.camera->rig_from_ahat()));
        }
      },
      progress);
  return records;
}

StageSamples CollectStageSamples(const MarkerSource& source,
                                 const MarkerDetectionOptions& detection,
                                 const ToolGeometry& structure, const StageSampleOptions& options,
                                 const Progress& progress) {
  std::vector<StageFrame> frames;
  ForEachFrameMarkers(
      source, detection,
      [&](std::size_t, const AhatFrame& frame, std::vector<DetectedMarker>& markers) {
        frames.push_back({frame.timestamp_s(), std::move(markers)});
      },
      progress);
  std::vector<std::vector<StageFrame>> runs =
      SplitRuns(std::move(frames), structure, options.split_jump_mm);
  StageSamples result;
  for (std::size_t r = 0; r < runs.size(); ++r) {
    StageRun run;
    run.run = r;
    run.frames = runs[r].size();
    try {
      StageRangeErrorOptions stage_options = options.stage;
      if (options.speed_mm_s) stage_options.known_speed_mm_per_s = *options.speed_mm_s;
      const StageRangeErrorResult stage =
          MeasureMarkerRangeErrors(runs[r], structure, stage_options);
      const double speed = stage.fitted_speed_mm_per_s;
      run.frames_used = stage.frames_used;
      run.speed_mm_s = speed;
      run.line_rms_mm = stage.line_rms_mm;
      run.samples = stage.samples.size();
      if (options.speed_mm_s &&
          std::abs(speed - *options.speed_mm_s) > options.speed_tolerance * *options.speed_mm_s) {
        run.dropped = "fitted speed differs from --speed-mm-s by more than 10 %";
      } else {
        result.samples.insert(result.samples.end(), stage.samples.begin(), stage.samples.end());
        result.frames_used += stage.frames_used;
      }
    } catch (const std::invalid_argument& e) {
      run.dropped = e.what();
    }
    result.runs.push_back(run);
  }
  return result;
}

}  // namespace tofnav
