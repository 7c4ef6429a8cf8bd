// SPDX-License-Identifier: BSD-3-Clause
// tofnav evaluate materials: depth error per material vs the IR-tape reference plane and truth.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <sstream>

#include "commands.hpp"
#include "config_json.hpp"
#include "evaluate.hpp"
#include "progress.hpp"
#include "tofnav/casefile/marker_range_json.hpp"
#include "tofnav/core/units.hpp"
#include "tofnav/correction/marker_range_model.hpp"
#include "tofnav/correction/material_study.hpp"
#include "tofnav/evaluation/material_evaluate.hpp"
#include "tofnav/sensor/ahat_recording.hpp"

namespace tofnav {
namespace {

using Json = nlohmann::json;

Json DepthStatsJson(const Summary& s) {  // a Summary of depth errors [mm]
  return {{"count", s.count}, {"median_mm", s.median}, {"iqr_mm", s.iqr()}, {"q1_mm", s.p25},
          {"q3_mm", s.p75},   {"mean_mm", s.mean},     {"std_mm", s.sd}};
}

Json CellsJson(const std::vector<MaterialCell>& cells, const std::vector<std::string>& names) {
  Json out = Json::array();
  for (const MaterialCell& c : cells) {
    Json j{{"material", names[static_cast<std::size_t>(c.material)]},
           {"vs_reference", DepthStatsJson(c.vs_reference_mm)},
           {"vs_truth", DepthStatsJson(c.vs_truth_mm)}};
    if (std::isfinite(c.depth_max_mm)) j["depth_mm"] = {c.depth_min_mm, c.depth_max_mm};
    if (std::isfinite(c.angle_max_rad)) {
      j["angle_deg"] = {c.angle_min_rad * kRadToDeg, c.angle_max_rad * kRadToDeg};
    }
    out.push_back(j);
  }
  return out;
}

// Rows of one axis (depth or angle), one column per material: median vs reference (vs truth).
void PrintAxis(const std::string& title, const std::vector<MaterialCell>& cells,
               const std::vector<std::string>& names, bool depth) {
  std::map<double, std::map<int, const MaterialCell*>> rows;
  std::map<int, bool> used;
  for (const MaterialCell& c : cells) {
    rows[depth ? c.depth_min_mm : c.angle_min_rad][c.material] = &c;
    used[c.material] = true;
  }
  std::cout << "\n"
            << title << ": median error vs reference (vs truth) [mm]\n"
            << std::setw(11) << (depth ? "range mm" : "angle deg");
  for (const auto& [m, _] : used) std::cout << std::setw(22) << names[static_cast<std::size_t>(m)];
  std::cout << "\n";
  for (const auto& [lo, row] : rows) {
    const MaterialCell& first = *row.begin()->second;
    const double hi = depth ? first.depth_max_mm : first.angle_max_rad;
    const double scale = depth ? 1.0 : kRadToDeg;
    std::ostringstream bin;
    bin << std::setprecision(0) << std::fixed << lo * scale << "-" << hi * scale;
    std::cout << std::setw(11) << bin.str();
    for (const auto& [m, _] : used) {
      const auto it = row.find(m);
      std::ostringstream cell;
      if (it != row.end()) {
        cell << std::fixed << std::setprecision(2) << it->second->vs_reference_mm.median << " ("
             << it->second->vs_truth_mm.median << ")";
      }
      std::cout << std::setw(22) << cell.str();
    }
    std::cout << "\n";
  }
}

}  // namespace

int RunEvaluateMaterials(int argc, char** argv) {
  CLI::App app{
      "Depth error per material against the IR-tape reference plane (paper Sec. III-A.2) and "
      "against the simulator's truth, by depth and incidence angle (docs/correction.md)",
      "tofnav evaluate materials"};
  AddConfigOptions(app);
  SimulatedRunArgs run;
  run.max_frames = 180;
  std::filesystem::path frf_path;
  double depth_bin_mm = 50.0, angle_bin_deg = 10.0;
  MaterialEvaluationOptions settings;
  run.AddOptions(app, "simulator output folder (truth.json)");
  app.add_option("--marker-error", frf_path, "f_rf curve: Eq. (2) on the tape ranges");
  app.add_option("--ab-threshold", settings.ab_threshold, "AB counts of IR-tape pixels")
      ->check(CLI::PositiveNumber);
  app.add_option("--margin-px", settings.margin_px, "pixels dropped at object and tape edges")
      ->check(CLI::Range(0, 10));
  app.add_option("--depth-bin-mm", depth_bin_mm, "depth bin width [mm]")
      ->check(CLI::PositiveNumber);
  app.add_option("--angle-bin-deg", angle_bin_deg, "incidence angle bin width [deg]")
      ->check(CLI::PositiveNumber);
  TOFNAV_PARSE(app, argc, argv);

  const bool json_out = run.json, quiet = run.quiet;
  settings.max_frames = run.max_frames;
  settings.study.depth_bin_mm = depth_bin_mm;
  settings.study.angle_bin_rad = angle_bin_deg / kRadToDeg;
  const AhatCamera camera = run.Camera();
  const std::unique_ptr<AhatRecording> recording = run.Open();
  if (!frf_path.empty()) settings.frf = ReadMarkerRangeJson(frf_path).model;
  SimulationTruth simulation = ReadSimulationTruth(run.truth_dir, run.scenario_name);
  ProgressBar progress("evaluate materials", quiet || json_out);
  const MaterialEvaluation evaluation =
      EvaluateMaterials(*recording, camera, simulation, run.truth_dir / "truth.json", settings,
                        [&](std::size_t done, std::size_t total) { progress.Update(done, total); });
  const MaterialStudyResult& result = evaluation.result;
  const std::vector<std::string>& names = evaluation.material_names;
  const std::vector<double>& plane_rms = evaluation.plane_rms_mm;
  const std::size_t frames = evaluation.frames;
  const Summary plane_rms_mm = SummariseDepthErrors({plane_rms.begin(), plane_rms.end()});
  if (json_out) {
    std::cout << WithOptions(
                     Json{{"frames", frames},
                          {"frames_with_plane", plane_rms.size()},
                          {"marker_error_applied", settings.frf.has_value()},
                          {"reference_plane_rms_mm_median", plane_rms_mm.median},
                          {"overall", CellsJson(result.overall, names)},
                          {"by_depth", CellsJson(result.by_depth, names)},
                          {"by_angle", CellsJson(result.by_angle, names)},
                          {"by_depth_and_angle", CellsJson(result.by_depth_and_angle, names)}},
                     app)
                     .dump(2)
              << "\n";
    return EXIT_SUCCESS;
  }
  std::cout << "material depth error [mm], " << frames << " frames (" << plane_rms.size()
            << " with a reference plane, median plane RMS " << std::fixed << std::setprecision(2)
            << plane_rms_mm.median << " mm), f_rf " << (settings.frf ? "applied" : "not applied")
            << "\n"
            << std::left << std::setw(18) << "material" << std::right << std::setw(10) << "pixels"
            << std::setw(12) << "ref median" << std::setw(8) << "IQR" << std::setw(8) << "std"
            << std::setw(12) << "true median" << std::setw(8) << "IQR" << std::setw(12)
            << "ref - true\n";
  for (const MaterialCell& c : result.overall) {
    std::cout << std::left << std::setw(18) << names[static_cast<std::size_t>(c.material)]
              << std::right << std::setw(10) << c.vs_reference_mm.count << std::setw(12)
              << c.vs_reference_mm.median << std::setw(8) << c.vs_reference_mm.iqr() << std::setw(8)
              << c.vs_reference_mm.sd << std::setw(12) << c.vs_truth_mm.median << std::setw(8)
              << c.vs_truth_mm.iqr() << std::setw(11)
              << c.vs_reference_mm.median - c.vs_truth_mm.median << "\n";
  }
  PrintAxis("by depth", result.by_depth, names, true);
  PrintAxis("by incidence angle", result.by_angle, names, false);
  return EXIT_SUCCESS;
}

namespace {
[[maybe_unused]] const bool kMaterialsRegistered = RegisterEvaluator(
    {"materials", "depth error per material vs the IR-tape reference plane and truth",
     RunEvaluateMaterials});
}  // namespace

}  // namespace tofnav
