// SPDX-License-Identifier: BSD-3-Clause
// tool-define: a tool's marker geometry from many frames of a static or moving tool (section 7).
#pragma once

#include <optional>
#include <span>
#include <string>
#include <vector>

#include "tofnav/core/rigid3d.hpp"
#include "tofnav/markers/marker_detection.hpp"
#include "tofnav/tracking/tool_geometry.hpp"

namespace tofnav {

struct ToolDefinitionOptions {
  std::string name = "tool";
  MarkerType marker_type = MarkerType::kSphere;
  double marker_diameter_mm = 11.5;
  int marker_count = 0;             // 0: the most frequent detection count of the frames
  double match_tolerance_mm = 2.5;  // inter-marker distance tolerance against the model
  double max_fre_mm = 1.0;          // frames fitting the model worse are dropped
  double outlier_factor = 3.0;      // dimensionless: marker observations beyond this x RMS drop
  int min_frames = 20;              // frames with a match needed
  int iterations = 4;               // generalised Procrustes rounds
  /// f_rf's entrance-angle term (MarkerRangeModel::entrance_gain_mm_per_rad, docs/tracking.md 4),
  /// applied to sphere markers before their centres are taken; disc markers keep their ranges
  /// (their entrance angle needs the tool's plane, which the definition is still looking for).
  double marker_entrance_gain_mm_per_rad = 0.0;
  void Check() const;  // throws std::invalid_argument naming the bad field
};

struct ToolDefinitionResult {
  /// Markers in the new `tool` frame: origin at their centroid, axes along their principal
  /// directions (x the widest spread), signs fixed by the first markers; reference-frame order.
  ToolGeometry tool;
  std::vector<double> marker_rms_mm;  // scatter of each marker's observations about the model
  std::vector<int> marker_observations;
  double definition_rms_mm = 0.0;  // over every used observation
  int frames_used = 0;             // frames that matched the model with >= 3 markers
  int frames_rejected = 0;         // frames with too few markers or no consistent match
  std::vector<std::optional<Rigid3d>> ahat_from_tool;  // per input frame, when used
};

/// Builds a tool from per-frame detections (docs/tracking.md section 10, ours): the reference frame
/// is the one with the modal marker count whose sorted distances are closest to the median; every
/// frame is matched to the model by inter-marker distances (so marker order never depends on
/// position, flickering markers and spurious blobs are tolerated, the tool may move); then
/// generalised Procrustes: Kabsch each frame onto the model, average with outlier rejection,
/// repeat. Throws std::invalid_argument on bad options or when fewer than min_frames frames match
/// (the message says why).
ToolDefinitionResult DefineTool(std::span<const std::vector<DetectedMarker>> frames,
                                const ToolDefinitionOptions& options = {});

}  // namespace tofnav
