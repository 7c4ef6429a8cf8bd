// SPDX-License-Identifier: BSD-3-Clause
// Tool poses (`tofnav track`) against a simulation's truth.json: per-tool tracking figures
// (`tofnav evaluate tracking`, the demo's tracking stage; docs/tracking.md).
#pragma once

#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "tofnav/casefile/tool_poses_io.hpp"
#include "tofnav/tracking/tracking_evaluation.hpp"

namespace tofnav {

struct ToolTruthEvaluation {
  std::string name;
  ToolEvaluation evaluation;
  std::vector<ToolEvaluationFrame> frames;  // the compared frames, in record order
  std::vector<double> times_s;              // their timestamps
};

/// Per tool of `records` (in first-seen order): its frames matched to truth.json's by index and
/// timestamp, "fully visible" from the truth's visible markers (each seen by >= min_marker_pixels
/// pixels, within its material's retro-reflection cut-off, its blob 2 px apart from every other),
/// then EvaluateToolTracking with the truth's marker geometry. Throws std::runtime_error on a
/// truth.json that is not a simulation's, a tool or frame it lacks, or differing timestamps.
std::vector<ToolTruthEvaluation> EvaluateTrackingAgainstTruth(
    std::span<const ToolPoseRecord> records, const std::filesystem::path& truth_path,
    const TrackingEvaluationOptions& options = {}, int min_marker_pixels = 4);

}  // namespace tofnav
