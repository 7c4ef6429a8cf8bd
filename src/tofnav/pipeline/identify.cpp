// SPDX-License-Identifier: BSD-3-Clause
// Identification from a recording: frame preparation, two stages, the skin placed once.
#include "tofnav/pipeline/identify.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "tofnav/correction/initial_pose.hpp"
#include "tofnav/imaging/skin.hpp"
#include "tofnav/tracking/rotation_smoothing.hpp"
#include "tofnav/tracking/tool_tracker.hpp"

namespace tofnav {
namespace {

// The frame's markers, located and corrected by f_rf as `tofnav track` has them.
struct FrameMarkers {
  std::vector<DetectedMarker> markers;
  std::vector<DroppedBlob> dropped;
};

FrameMarkers LocateCorrected(const AhatFrame& frame, const AhatCamera& camera,
                             const MarkerRangeModel& marker_range,
                             const IdentifyRecordingOptions& options) {
  MarkerDetectionResult detected = LocateMarkers(frame, camera, options.detection);
  FrameMarkers out{std::move(detected.markers), std::move(detected.dropped)};
  if (!marker_range.empty())
    out.markers = CorrectMarkerRanges(std::move(out.markers), marker_range);
  return out;
}

// The reference tool's pose in this frame alone, when measured with min_markers or more.
std::optional<Rigid3d> ReferenceToolFromAhat(const FrameMarkers& m, double timestamp_s,
                                             ToolTracker& tracker, int min_markers) {
  tracker.Reset();  // frames are far apart: each is measured on its own
  const TrackingFrame tracked = tracker.Track(m.markers, timestamp_s, std::nullopt, m.dropped);
  const ToolPoseResult& pose = tracked.tools.front().measurement;
  if (!pose.ahat_from_tool || pose.used_markers < min_markers) return std::nullopt;
  return pose.ahat_from_tool->Inverse();
}

// Blanks (range and AB 0) the pixels within the blob's radius + margin of every marker matched to
// a tool; returns the matched markers per tool.
std::vector<int> BlankToolMarkers(AhatFrame& frame, const FrameMarkers& m, ToolTracker& tracker,
                                  const IdentifyRecordingOptions& options) {
  const std::vector<DetectedMarker>& markers = m.markers;
  tracker.Reset();  // frames are far apart: each is matched on its own
  const TrackingFrame tracked =
      tracker.Track(markers, frame.timestamp_s(), std::nullopt, m.dropped);
  std::vector<int> blanked(tracked.tools.size(), 0);
  const int width = frame.range_mm.width(), height = frame.range_mm.height();
  for (std::size_t t = 0; t < tracked.tools.size(); ++t) {
    for (const int d : tracked.tools[t].measurement.marker_detection) {
      if (d < 0) continue;
      const DetectedMarker& dm = markers[static_cast<std::size_t>(d)];
      const double r = std::sqrt(dm.area_px / std::numbers::pi) + options.tool_marker_margin_px;
      const int u0 = std::max(0, static_cast<int>(std::floor(dm.pixel.x() - r)));
      const int u1 = std::min(width - 1, static_cast<int>(std::ceil(dm.pixel.x() + r)));
      const int v0 = std::max(0, static_cast<int>(std::floor(dm.pixel.y() - r)));
      const int v1 = std::min(height - 1, static_cast<int>(std::ceil(dm.pixel.y() + r)));
      for (int v = v0; v <= v1; ++v) {
        for (int u = u0; u <= u1; ++u) {
          if (std::hypot(u - dm.pixel.x(), v - dm.pixel.y()) > r) continue;
          frame.range_mm(u, v) = 0;
          frame.ab(u, v) = 0;
        }
      }
      ++blanked[t];
    }
  }
  return blanked;
}

// The picked frames' reference poses (tool_from_ahat, by recording index) with their
// orientations smoothed in `world` (tracking/rotation_smoothing.hpp); returns how many.
std::int64_t SmoothReferenceRotations(const AhatCamera& camera, const std::vector<int>& picked,
                                      const std::vector<std::optional<Rigid3d>>& world_from_rig,
                                      const std::vector<double>& time_s,
                                      const RotationSmoothingOptions& options,
                                      std::vector<std::optional<Rigid3d>>& tool_from_ahat) {
  std::vector<std::optional<Rigid3d>> ahat_from_tool(picked.size()), world_from_ahat(picked.size());
  std::vector<double> times(picked.size());
  for (std::size_t k = 0; k < picked.size(); ++k) {
    const auto i = static_cast<std::size_t>(picked[k]);
    times[k] = time_s[i];
    if (tool_from_ahat[i]) ahat_from_tool[k] = tool_from_ahat[i]->Inverse();
    if (world_from_rig[i]) world_from_ahat[k] = *world_from_rig[i] * camera.rig_from_ahat();
  }
  const std::size_t count = SmoothAhatRotations(ahat_from_tool, world_from_ahat, times, options);
  for (std::size_t k = 0; k < picked.size(); ++k) {
    if (ahat_from_tool[k])
      tool_from_ahat[static_cast<std::size_t>(picked[k])] = ahat_from_tool[k]->Inverse();
  }
  return static_cast<std::int64_t>(count);
}

// Stage 1 (smoothness only) refitted on each of options.placement_subsets frame subsets, as
// further starts for the skin's first placement; a subset without a marker patch adds none.
void AppendSubsetStarts(std::span<const IdentificationFrame> frames,
                        const IdentifyRecordingOptions& options,
                        std::vector<DepthErrorModel>& starts,
                        std::vector<PlacementCandidate>& candidates) {
  const int n = options.placement_subsets;
  for (int k = 0; k < n; ++k) {
    std::vector<IdentificationFrame> subset;
    for (std::size_t i = 0; i < frames.size(); ++i) {
      if (static_cast<int>(i % static_cast<std::size_t>(n)) != k) subset.push_back(frames[i]);
    }
    try {
      starts.push_back(IdentifyDepthModel(subset, nullptr, options.start, options.identification));
    } catch (const std::invalid_argument&) {
      continue;  // no marker patch left in this subset
    }
    // C1 at the first stage-1 model's references (each fit centres its own: docs/correction.md
    // 2.7), so that the candidates compare.
    const DepthErrorModel& first = starts.front();
    candidates.push_back(
        {"stage 1 without frames " + std::to_string(k) + " mod " + std::to_string(n), true,
         starts.back().WithReferences(first.theta_reference_rad, first.ab_reference).c1_mm});
  }
}

}  // namespace

void FrameLeaveOut::Check() const {
  if (every < 2 || subset < 0 || subset >= every) {
    throw std::invalid_argument("FrameLeaveOut: every must be >= 2 and 0 <= subset < every");
  }
}

IdentifyRecordingResult IdentifyFromRecording(
    const AhatRecording& recording, const AhatCamera& camera,
    const std::optional<MarkerRangeModel>& marker_range, const SurfaceIndex* skin,
    const IdentifyRecordingOptions& options,
    const std::function<void(std::size_t, std::size_t)>& progress) {
  if (options.placement_subsets < 0 || options.placement_subsets == 1) {
    throw std::invalid_argument("IdentifyRecordingOptions: placement_subsets is 0 or at least 2");
  }
  std::vector<int> picked =
      EvenSubsample(static_cast<int>(recording.frame_count()), options.max_frames);
  if (options.leave_out) {
    options.leave_out->Check();
    std::vector<int> kept;
    for (std::size_t k = 0; k < picked.size(); ++k) {
      if (static_cast<int>(k % static_cast<std::size_t>(options.leave_out->every)) !=
          options.leave_out->subset) {
        kept.push_back(picked[k]);
      }
    }
    picked = std::move(kept);
  }
  IdentifyRecordingResult result;
  const MarkerRangeModel frf = marker_range.value_or(MarkerRangeModel{});
  std::optional<ToolTracker> tracker, reference;
  std::vector<std::int64_t> left_out(options.exclude_tools.size(), 0);
  ToolTrackerOptions tracking;  // f_rf's entrance-angle term for disc tools (docs/tracking.md 4)
  tracking.pose.marker_entrance_gain_mm_per_rad = frf.entrance_gain_mm_per_rad;
  if (!options.exclude_tools.empty()) tracker.emplace(options.exclude_tools, tracking);
  if (options.reference_tool) reference.emplace(std::vector{*options.reference_tool}, tracking);
  // A headframe of one plate counts whole (docs/correction.md 2): its frames are all it has.
  const int min_reference_markers =
      options.reference_tool
          ? std::min(options.min_reference_markers,
                     static_cast<int>(options.reference_tool->markers_in_tool.size()))
          : options.min_reference_markers;
  std::vector<std::optional<Rigid3d>> tool_from_ahat(recording.frame_count());
  std::vector<std::optional<Rigid3d>> world_from_rig(recording.frame_count());
  std::vector<double> time_s(recording.frame_count(), 0.0);
  std::vector<IdentificationFrame> frames = PrepareIdentificationFrames(
      picked,
      [&](int i) {
        AhatFrame frame = recording.ReadFrame(static_cast<std::size_t>(i));
        if (options.prepare_frame) options.prepare_frame(frame);
        if (!tracker && !reference) return frame;
        const FrameMarkers markers = LocateCorrected(frame, camera, frf, options);
        if (reference) {
          world_from_rig[static_cast<std::size_t>(i)] = frame.world_from_rig;
          time_s[static_cast<std::size_t>(i)] = frame.timestamp_s();
          tool_from_ahat[static_cast<std::size_t>(i)] = ReferenceToolFromAhat(
              markers, frame.timestamp_s(), *reference, min_reference_markers);
        }
        if (tracker) {
          const std::vector<int> blanked = BlankToolMarkers(frame, markers, *tracker, options);
          int any = 0;
          for (std::size_t t = 0; t < blanked.size(); ++t) {
            left_out[t] += blanked[t];
            any += blanked[t];
          }
          if (any > 0) ++result.frames_with_tool_markers;
        }
        return frame;
      },
      camera, frf, options.sampling, progress);
  if (reference && options.smooth_reference_rotation) {
    result.frames_reference_rotation_smoothed =
        SmoothReferenceRotations(camera, picked, world_from_rig, time_s,
                                 options.reference_rotation_smoothing, tool_from_ahat);
  }
  for (IdentificationFrame& f : frames) {
    f.tool_from_ahat = tool_from_ahat[static_cast<std::size_t>(f.index)];
    if (f.tool_from_ahat) ++result.frames_with_reference_tool;
  }
  for (std::size_t t = 0; t < left_out.size(); ++t) {
    result.tool_marker_observations_left_out.emplace_back(options.exclude_tools[t].name,
                                                          left_out[t]);
  }
  // Stage 1: smoothness only (no CT needed, cheap). Stage 2 (with a skin): both costs from there,
  // with the skin registered once to head clouds corrected by the stage-1 model.
  DepthErrorModel& model = result.file.model;
  model = IdentifyDepthModel(frames, nullptr, options.start, options.identification);
  if (skin != nullptr) {
    // The skin's first placement is a coarse search on one merged cloud: with the stage-1 model's
    // ranges it can settle in a wrong basin (ct-mirror-discs, session 17: 38 % inliers, frames
    // 5 mm off, against 66 % from the start model; held-out mr-drift-drops merged through
    // `world`, session 23: 29 % against 36 % from stage 1 on a frame subset). Every start is
    // tried; the one that keeps the most of the cloud within the ICP's finest gate is kept
    // (docs/correction.md 2.3).
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<DepthErrorModel> starts = {model, options.start};
    result.placement_candidates = {
        {"stage-1 model", false, model.c1_mm},
        {"start model", false,
         options.start.WithReferences(model.theta_reference_rad, model.ab_reference).c1_mm}};
    AppendSubsetStarts(frames, options, starts, result.placement_candidates);
    if (options.joint_start) {
      starts.push_back(*options.joint_start);
      result.placement_candidates.push_back(
          {"another run's model", false,
           options.joint_start->WithReferences(model.theta_reference_rad, model.ab_reference)
               .c1_mm});
    }
    for (std::size_t k = 0; k < options.placement_guesses.size(); ++k)
      result.placement_candidates.push_back({"another run's placement", false, model.c1_mm});
    BestStartPlacement placement =
        InitialImageFromBestStart(frames, *skin, starts, {}, options.placement_guesses);
    for (std::size_t i = 0; i < result.placement_candidates.size(); ++i)
      result.placement_candidates[i].inlier_fraction = placement.inlier_fractions[i];
    result.placement_kept = placement.start;
    const double stage1_s =
        model.report.seconds +
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const InitialPoseResult& pose = placement.pose;
    const CorrectnessTarget target{skin, pose.image_from_ahat};
    result.reference_frame = frames[static_cast<std::size_t>(pose.reference_frame)].index;
    result.icp_rmse_mm = pose.registration.icp.rmse_mm;
    result.icp_inlier_fraction = pose.registration.icp.inlier_fraction;
    result.placed_through_tool = pose.through_tool;
    result.placement = MergedPlacement{pose.image_from_merged, pose.through_tool};
    model = IdentifyDepthModel(frames, &target, options.joint_start.value_or(model),
                               options.identification);
    model.report.seconds += stage1_s;
    if (options.cross_validate_folds >= 2) {
      model.report.cross_validation =
          CrossValidateModels(frames, &target, DefaultModelCandidates(),
                              options.cross_validate_folds, options.identification);
    }
  } else if (options.cross_validate_folds >= 2) {
    model.report.cross_validation =
        CrossValidateModels(frames, nullptr, DefaultModelCandidates(), options.cross_validate_folds,
                            options.identification);
  }
  model.multipath = options.sampling.multipath;
  result.file.marker_range = marker_range;
  return result;
}

TriangleMesh SkinIsoSurface(const CtVolume& ct, std::optional<double> iso_hu) {
  SkinOptions options;
  options.threshold = iso_hu;
  return ExtractSkin(ct, options).mesh;
}

}  // namespace tofnav
