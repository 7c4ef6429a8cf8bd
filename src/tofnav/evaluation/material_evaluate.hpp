// SPDX-License-Identifier: BSD-3-Clause
// The material study of Sec. III-A.2 on a simulated recording: each material's depth error
// against the IR-tape reference plane and against the simulator's truth, by depth and incidence
// (tofnav evaluate materials; docs/correction.md).
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "tofnav/correction/marker_range_model.hpp"
#include "tofnav/correction/material_study.hpp"
#include "tofnav/evaluation/truth_hits.hpp"
#include "tofnav/markers/marker_detection.hpp"
#include "tofnav/sensor/ahat_camera.hpp"
#include "tofnav/sensor/ahat_recording.hpp"

namespace tofnav {

struct MaterialEvaluationOptions {
  double ab_threshold = kMarkerAbThreshold;  // AB counts: IR-tape pixels
  int margin_px = 3;  // pixels this close to another object or a tape edge: mixed, left out
  std::optional<MarkerRangeModel> frf;  // Eq. (2) on the tape ranges when given
  MaterialStudyOptions study;
  int max_frames = 180;  // frames studied, evenly spread over the recording
};

struct MaterialEvaluation {
  std::vector<std::string> material_names;  // the scene's, indexed by MaterialCell::material
  MaterialStudyResult result;
  std::vector<double> plane_rms_mm;  // per studied frame with a reference plane
  std::size_t frames = 0;            // frames studied
};

/// Per studied frame: the tape pixels (AB threshold, eroded by the margin, Eq. 2 applied) fitted
/// as the reference plane, then every interior material pixel against it and against the truth
/// ray cast of the frame. `truth_json` names truth.json in errors (IoError when its frame count
/// differs from the recording's); progress(done, total) after each frame.
/// `truth`'s scene is posed frame by frame.
MaterialEvaluation EvaluateMaterials(const AhatRecording& recording, const AhatCamera& camera,
                                     SimulationTruth& truth,
                                     const std::filesystem::path& truth_json,
                                     const MaterialEvaluationOptions& options,
                                     const std::function<void(std::size_t, std::size_t)>& progress);

}  // namespace tofnav
