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
#include "tofnav/correction/identification_frame.hpp"
#include "tofnav/correction/marker_range_model.hpp"
#include "tofnav/correction/material_study.hpp"
#include "tofnav/evaluation/truth_hits.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/markers/marker_detection.hpp"
#include "tofnav/recording/hl2ss_calibration.hpp"
#include "tofnav/sensor/ahat_recording.hpp"

namespace tofnav {
namespace {

using Json = nlohmann::json;
constexpr double kRadToDeg = 180.0 / std::numbers::pi;

struct Settings {
  double ab_threshold = kMarkerAbThreshold;  // AB counts: IR-tape pixels
  int margin_px = 3;  // pixels this close to another object or a tape edge: mixed
  std::optional<MarkerRangeModel> frf;
};

bool ValidRange(std::uint16_t r) { return r > 0 && r < kAhatInvalidRange; }

// True when every pixel within the margin satisfies `inside`.
template <typename Inside>
bool Interior(const AhatFrame& frame, int u, int v, int margin, Inside inside) {
  for (int dv = -margin; dv <= margin; ++dv) {
    for (int du = -margin; du <= margin; ++du) {
      if (!frame.ab.Contains(u + du, v + dv) || !inside(u + du, v + dv)) return false;
    }
  }
  return true;
}

// One frame: the tape pixels (AB threshold, eroded by the margin, Eq. 2 applied) fitted as the
// reference plane, then every interior material pixel against it and against truth.
bool StudyFrame(const AhatFrame& frame, const TruthHits& truth, const AhatCamera& camera,
                const Settings& settings, MaterialStudy& study, std::vector<double>& plane_rms) {
  const auto tape = [&](int u, int v) {
    return frame.ab(u, v) >= settings.ab_threshold && ValidRange(frame.range_mm(u, v)) &&
           camera.IsValid(u, v);
  };
  const auto ray = [&](int u, int v) { return camera.PixelRay(u, v).cast<double>().normalized(); };
  std::vector<Eigen::Vector3d> tape_points;
  std::vector<std::pair<int, int>> tape_pixels;
  for (int v = 0; v < frame.ab.height(); ++v) {
    for (int u = 0; u < frame.ab.width(); ++u) {
      if (!tape(u, v) || !Interior(frame, u, v, settings.margin_px, tape)) continue;
      const double range = frame.range_mm(u, v);
      tape_points.push_back(ray(u, v) *
                            (settings.frf ? CorrectMarkerRange(range, *settings.frf) : range));
      tape_pixels.emplace_back(u, v);
    }
  }
  const std::optional<ReferencePlane> plane = FitReferencePlane(tape_points);
  if (!plane) return false;
  plane_rms.push_back(plane->rms_mm);
  const auto add = [&](int material, const Eigen::Vector3d& x, float truth_range_mm) {
    const std::optional<double> e = ReferenceDepthErrorMm(*plane, x);
    if (!e) return;
    const double range = x.norm();
    study.Add({material, static_cast<float>(range - *e),
               static_cast<float>(PlaneIncidenceRad(*plane, x)), static_cast<float>(*e),
               truth_range_mm > 0.0f ? static_cast<float>(range - truth_range_mm) : NAN});
  };
  for (std::size_t i = 0; i < tape_points.size(); ++i) {
    const auto [u, v] = tape_pixels[i];
    if (truth.material(u, v) >= 0) add(truth.material(u, v), tape_points[i], truth.range_mm(u, v));
  }
  for (int v = 0; v < frame.ab.height(); ++v) {
    for (int u = 0; u < frame.ab.width(); ++u) {
      const int object = truth.object(u, v);
      if (object < 0 || tape(u, v) || !ValidRange(frame.range_mm(u, v))) continue;
      const auto same = [&](int x, int y) { return truth.object(x, y) == object && !tape(x, y); };
      if (!Interior(frame, u, v, settings.margin_px, same)) continue;
      add(truth.material(u, v), ray(u, v) * frame.range_mm(u, v), truth.range_mm(u, v));
    }
  }
  return true;
}

Json StatsJson(const Summary& s) {  // a Summary of depth errors [mm]
  return {{"count", s.count}, {"median_mm", s.median}, {"iqr_mm", s.iqr()}, {"q1_mm", s.p25},
          {"q3_mm", s.p75},   {"mean_mm", s.mean},     {"std_mm", s.sd}};
}

Json CellsJson(const std::vector<MaterialCell>& cells, const std::vector<std::string>& names) {
  Json out = Json::array();
  for (const MaterialCell& c : cells) {
    Json j{{"material", names[static_cast<std::size_t>(c.material)]},
           {"vs_reference", StatsJson(c.vs_reference_mm)},
           {"vs_truth", StatsJson(c.vs_truth_mm)}};
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
  Settings settings;
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

  const std::filesystem::path& truth_dir = run.truth_dir;
  const bool json_out = run.json, quiet = run.quiet;
  const int max_frames = run.max_frames;
  const AhatCamera camera = run.Camera();
  const std::unique_ptr<AhatRecording> recording = run.Open();
  if (!frf_path.empty()) settings.frf = ReadMarkerRangeJson(frf_path).model;
  SimulationTruth simulation = ReadSimulationTruth(truth_dir, run.scenario_name);
  sim::Scenario& scenario = simulation.scenario;
  sim::SceneRaycaster caster(scenario.scene);
  const Json& truth_frames = simulation.truth.at("frames");
  if (truth_frames.size() != recording->frame_count()) {
    throw IoError(truth_dir / "truth.json", std::nullopt,
                  "frame count differs from the recording's");
  }
  std::vector<std::string> names;
  for (const sim::Material& m : scenario.scene.materials) names.push_back(m.name);
  MaterialStudyOptions study_options;
  study_options.depth_bin_mm = depth_bin_mm;
  study_options.angle_bin_rad = angle_bin_deg / kRadToDeg;
  MaterialStudy study(names, study_options);
  std::vector<double> plane_rms;
  const std::vector<int> picked = EvenSubsample(static_cast<int>(truth_frames.size()), max_frames);
  ProgressBar progress("evaluate materials", quiet || json_out);
  for (std::size_t n = 0; n < picked.size(); ++n) {
    const auto i = static_cast<std::size_t>(picked[n]);
    const AhatFrame frame = recording->ReadFrame(i);
    const TruthHits hits = CastTruthHits(scenario.scene, caster, truth_frames[i], camera);
    StudyFrame(frame, hits, camera, settings, study, plane_rms);
    progress.Update(n + 1, picked.size());
  }
  const MaterialStudyResult result = study.Summarise();
  const Summary plane_rms_mm = SummariseDepthErrors({plane_rms.begin(), plane_rms.end()});
  if (json_out) {
    std::cout << WithOptions(
                     Json{{"frames", picked.size()},
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
  std::cout << "material depth error [mm], " << picked.size() << " frames (" << plane_rms.size()
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
[[maybe_unused]] const bool kRegistered = RegisterEvaluator(
    {"materials", "depth error per material vs the IR-tape reference plane and truth",
     RunEvaluateMaterials});
}  // namespace

}  // namespace tofnav
