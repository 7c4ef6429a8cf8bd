// SPDX-License-Identifier: BSD-3-Clause
// Depth error per object against the simulator's truth range, before and after a depth model
// (`tofnav evaluate depth`, the demo's depth stage; paper Table I layout).
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "tofnav/casefile/depth_model_json.hpp"
#include "tofnav/core/statistics.hpp"
#include "tofnav/sensor/ahat_camera.hpp"
#include "tofnav/sensor/ahat_recording.hpp"
#include "tofnav/sim/scenario.hpp"

namespace tofnav {

/// One object's signed depth errors within one bin of the true surface's incidence angle or range.
struct DepthErrorBin {
  double from = 0.0, to = 0.0;  // [deg] or [mm], as the list holding it says
  std::size_t pixels = 0;
  double before_median_mm = 0.0;
  std::optional<double> after_median_mm;  // with a depth model
};

struct ObjectDepthError {
  std::string name;  // scene object
  /// "target": the patient's object, the one the head model is identified on; "other": another
  /// object of a patient scene (the head model applied for reference only); "object": no patient.
  std::string role;
  double head_region_percent = 0.0;  // share of its pixels in the automatic head region
  /// Signed depth errors (measured - true range) [mm]; before_mm.count: the object's pixels.
  Summary before_mm;
  std::optional<Summary> after_mm;  // with a depth model
  double reduction_percent = 0.0;   // 100 (1 - |after median| / |before median|)
  std::vector<float> before_errors_mm, after_errors_mm;  // the errors themselves (histograms)
  /// Per error: the true range [mm] and the true incidence angle [deg] (NaN where the truth's
  /// normal is unknown), from truth_range_f32.bin.
  std::vector<float> true_range_mm, true_incidence_deg;
  /// The errors by the true incidence (15 deg bins) and the true range (100 mm bins), bins with
  /// pixels only: where a depth model's residual lies (docs/correction.md 2.5).
  std::vector<DepthErrorBin> by_incidence_deg, by_range_mm;
};

struct DepthEvaluation {
  std::size_t frames = 0;
  std::string target_object;              // truth.json's patient object; empty without a patient
  std::vector<ObjectDepthError> objects;  // by name
};

/// Interior pixels of every scene object (2 px from another object, a marker or a depth edge) in
/// up to `max_frames` evenly spread frames of `recording`, against `truth_dir`'s truth.json poses
/// and truth_range_f32.bin (simulate --truth-depth); `scenario` is the one simulated (its meshes
/// label the pixels). With `model`, pixels its correction drops are left out of both columns.
/// Throws IoError on missing or inconsistent truth files.
DepthEvaluation EvaluateDepthAgainstTruth(
    const AhatRecording& recording, const AhatCamera& camera,
    const std::filesystem::path& truth_dir, sim::Scenario scenario,
    const std::optional<DepthModelFile>& model, int max_frames,
    const std::function<void(std::size_t, std::size_t)>& progress = {});

/// The bins as a JSON array: [{"from", "to", "pixels", "before_median_mm", "after_median_mm"
/// (with a model)}, ...]; `unit` names from/to ("deg" or "mm": keys "from_deg", "to_deg", ...).
nlohmann::json DepthErrorBinsJson(const std::vector<DepthErrorBin>& bins, const std::string& unit);

}  // namespace tofnav
