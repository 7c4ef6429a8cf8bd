// SPDX-License-Identifier: BSD-3-Clause
// Fidelity, the 3D-printing materials (paper Sec. III-A.2): the materials scene (15 depths
// 382-655 mm x 6 angles 5-45 deg) with a few frames per station, each material's depth error
// against the f_rf-corrected tape plane (EvaluateMaterials, the paper's own measurement).
#include <algorithm>
#include <cmath>

#include "tofnav/evaluation/fidelity.hpp"
#include "tofnav/evaluation/material_evaluate.hpp"
#include "tofnav/evaluation/truth_hits.hpp"
#include "tofnav/recording/open_recording.hpp"
#include "tofnav/sim/scenario_builtins.hpp"

namespace tofnav {
namespace {

constexpr std::size_t kMaterialMinCellPixels = 200;  // a bin with fewer pixels is not a figure
const char* const kMaterialSource = "paper Sec. III-A.2 (one plate, 15 depths x 6 angles)";

// Largest minus smallest mean error over one axis's cells of `material` (cells with enough
// pixels); NaN with fewer than two.
double CellMeanSpan(const std::vector<MaterialCell>& cells, int material) {
  double lo = INFINITY, hi = -INFINITY;
  int n = 0;
  for (const MaterialCell& c : cells) {
    if (c.material != material || c.vs_reference_mm.count < kMaterialMinCellPixels) continue;
    lo = std::min(lo, c.vs_reference_mm.mean);
    hi = std::max(hi, c.vs_reference_mm.mean);
    ++n;
  }
  return n >= 2 ? hi - lo : std::nan("");
}

}  // namespace

void FidelityMaterials(const FidelityOptions& options, const MarkerRangeModel& frf,
                       FidelityResult& result) {
  sim::Scenario scenario = sim::BuiltinScenario("materials");
  const auto per_station = static_cast<std::int64_t>(std::max(
      1.0, std::round(static_cast<double>(options.station_frames) * options.frames_scale)));
  std::int64_t frames = 0;
  for (sim::Mount& m : scenario.mounts) {
    if (m.motion.kind != sim::MotionKind::kSequence) continue;
    for (sim::Motion& station : m.motion.segments) station.segment_slots = per_station;
    frames = per_station * static_cast<std::int64_t>(m.motion.segments.size());
  }
  scenario.frames = frames;
  scenario.timing.drop_probability = 0.0;
  const std::filesystem::path dir = options.out / "materials";
  SimulateForFidelity(options, scenario, dir, "materials: simulate", options.seed);
  const RecordingWithCamera opened =
      OpenRecordingWithCamera(dir / "rm_depth_ahat.bin", dir / "calibration");
  SimulationTruth truth = ReadSimulationTruth(dir, "");
  MaterialEvaluationOptions settings;
  settings.frf = frf;
  settings.max_frames = static_cast<int>(frames);
  const MaterialEvaluation e =
      EvaluateMaterials(*opened.recording, *opened.camera, truth, dir / "truth.json", settings,
                        [&](std::size_t d, std::size_t t) {
                          if (options.progress) options.progress("materials: measure", d, t);
                        });
  const auto index = [&](const std::string& name) {
    const auto it = std::find(e.material_names.begin(), e.material_names.end(), name);
    if (it == e.material_names.end()) throw std::runtime_error("materials: no " + name);
    return static_cast<int>(it - e.material_names.begin());
  };
  const auto overall_mean = [&](int material) {
    for (const MaterialCell& c : e.result.overall)
      if (c.material == material) return c.vs_reference_mm.mean;
    throw std::runtime_error("materials: no pixel of " + e.material_names.at(material));
  };
  const int nylon = index("nylon"), pla = index("pla"), photopolymer = index("photopolymer");
  result.rows.push_back(MakeFidelityRow("materials", "PLA - nylon, mean difference [mm]",
                                        kMaterialSource, 14.57, std::nullopt,
                                        overall_mean(pla) - overall_mean(nylon)));
  const struct {
    const char* name;
    int material;
    double depth_mm, angle_mm;  // published largest changes over depth and over angle
  } published[] = {{"nylon", nylon, 6.10, 2.60},
                   {"PLA", pla, 5.29, 8.53},
                   {"photopolymer", photopolymer, 3.94, 3.81}};
  nlohmann::ordered_json materials = nlohmann::ordered_json::array();
  for (const auto& p : published) {
    const double over_depth = CellMeanSpan(e.result.by_depth, p.material);
    const double over_angle = CellMeanSpan(e.result.by_angle, p.material);
    result.rows.push_back(MakeFidelityRow("materials",
                                          std::string(p.name) + ": largest change over depth [mm]",
                                          kMaterialSource, p.depth_mm, std::nullopt, over_depth));
    result.rows.push_back(MakeFidelityRow("materials",
                                          std::string(p.name) + ": largest change over angle [mm]",
                                          kMaterialSource, p.angle_mm, std::nullopt, over_angle));
    materials.push_back({{"material", p.name},
                         {"mean_vs_reference_mm", overall_mean(p.material)},
                         {"change_over_depth_mm", over_depth},
                         {"change_over_angle_mm", over_angle}});
  }
  result.details["materials"] = {
      {"frames", frames}, {"frames_per_station", per_station}, {"materials", materials}};
}

}  // namespace tofnav
