// SPDX-License-Identifier: BSD-3-Clause
// The plan placed by navigation against a simulation's truth: entry-point and direction error
// (`tofnav evaluate guidance`, the demo's guidance stage; paper Sec. V).
#pragma once

#include <cstddef>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "tofnav/core/statistics.hpp"
#include "tofnav/imaging/trajectory.hpp"
#include "tofnav/pipeline/navigation_csv.hpp"

namespace tofnav {

struct TrajectoryGuidanceError {
  std::string name;
  Summary entry_mm;       // entry-point distance, as displayed relative to the head
  Summary direction_deg;  // angle between the placed and the true trajectory direction
};

struct GuidanceEvaluation {
  std::size_t frames = 0;     // placed frames matched to the truth
  std::size_t unmatched = 0;  // placed frames without a truth frame at their time
  Summary entry_mm, entry_world_mm, direction_deg;    // over every frame and trajectory
  std::vector<TrajectoryGuidanceError> trajectories;  // in plan order
};

/// For every placed frame and trajectory: the entry point and direction of the placed plan
/// relative to the head (rig_from_image: the recorded head pose cancels, Eq. 8) against the
/// truth's chain rig_from_ahat * ahat_from_tool * tool_from_image, and the entry in `world`
/// (with the headset's pose error). Throws std::runtime_error when truth_json is not a simulation
/// truth with a patient or no placed frame matches its timestamps.
GuidanceEvaluation EvaluateGuidanceAgainstTruth(std::span<const PlacedFrame> placed,
                                                const std::filesystem::path& truth_json,
                                                const std::vector<Trajectory>& plan);

}  // namespace tofnav
