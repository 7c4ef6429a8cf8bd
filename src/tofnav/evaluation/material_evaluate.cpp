// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/evaluation/material_evaluate.hpp"

#include <cmath>
#include <utility>

#include "tofnav/correction/identification_frame.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/sim/raycaster.hpp"

namespace tofnav {
namespace {

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
                const MaterialEvaluationOptions& settings, MaterialStudy& study,
                std::vector<double>& plane_rms) {
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
  std::optional<ReferencePlane> plane = FitReferencePlane(tape_points);
  if (!plane) return false;
  // f_rf's entrance-angle term (docs/tracking.md 4): the tape reads farther by g x its entrance
  // angle, the plane's against each pixel's ray; shortened, then the plane fitted again.
  if (settings.frf && settings.frf->entrance_gain_mm_per_rad != 0.0) {
    ShortenTapePoints(tape_points, plane->normal, settings.frf->entrance_gain_mm_per_rad);
    plane = FitReferencePlane(tape_points);
    if (!plane) return false;
  }
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

}  // namespace

MaterialEvaluation EvaluateMaterials(
    const AhatRecording& recording, const AhatCamera& camera, SimulationTruth& truth,
    const std::filesystem::path& truth_json, const MaterialEvaluationOptions& options,
    const std::function<void(std::size_t, std::size_t)>& progress) {
  sim::Scenario& scenario = truth.scenario;
  sim::SceneRaycaster caster(scenario.scene);
  const nlohmann::json& truth_frames = truth.truth.at("frames");
  if (truth_frames.size() != recording.frame_count()) {
    throw IoError(truth_json, std::nullopt, "frame count differs from the recording's");
  }
  MaterialEvaluation out;
  for (const sim::Material& m : scenario.scene.materials) out.material_names.push_back(m.name);
  MaterialStudy study(out.material_names, options.study);
  const std::vector<int> picked =
      EvenSubsample(static_cast<int>(truth_frames.size()), options.max_frames);
  for (std::size_t n = 0; n < picked.size(); ++n) {
    const auto i = static_cast<std::size_t>(picked[n]);
    const AhatFrame frame = recording.ReadFrame(i);
    const TruthHits hits = CastTruthHits(scenario.scene, caster, truth_frames[i], camera);
    StudyFrame(frame, hits, camera, options, study, out.plane_rms_mm);
    if (progress) progress(n + 1, picked.size());
  }
  out.frames = picked.size();
  out.result = study.Summarise();
  return out;
}

}  // namespace tofnav
