// SPDX-License-Identifier: BSD-3-Clause
// Fidelity, Table I "before" (paper Sec. IV-A): a head phantom static and facing the headset at
// about 300 mm, each pixel's range averaged over the frames, minus the true range; median and
// IQR over the head's interior pixels. The photopolymer and the nylon head.
#include <cmath>
#include <fstream>

#include "tofnav/core/statistics.hpp"
#include "tofnav/evaluation/fidelity.hpp"
#include "tofnav/evaluation/truth_hits.hpp"
#include "tofnav/recording/open_recording.hpp"
#include "tofnav/sim/scenario_fidelity.hpp"

namespace tofnav {
namespace {

constexpr double kPhantomDistanceMm = 300.0;  // "facing the camera at about 300 mm"
constexpr int kPhantomMarginPx = 2;           // pixels this close to another object: mixed
const char* const kPhantomSource = "paper Table I (phantom facing the camera, ~300 mm)";

struct PhantomFigures {
  double median_mm = 0.0, iqr_mm = 0.0;
  std::size_t pixels = 0;
};

// The head's per-pixel mean error over the frames of one facing-phantom simulation.
PhantomFigures MeasurePhantom(const FidelityOptions& options, const sim::Material& material,
                              const std::string& name) {
  const auto frames = static_cast<std::int64_t>(std::max(
      5.0, std::round(static_cast<double>(options.phantom_frames) * options.frames_scale)));
  SimulationTruth truth;
  truth.scenario =
      sim::FacingPhantomScenario(sim::PhantomHead(), material, kPhantomDistanceMm, frames);
  const std::filesystem::path dir = options.out / ("phantom_" + name);
  SimulateForFidelity(options, truth.scenario, dir, name + " phantom: simulate", options.seed);
  std::ifstream file(dir / "truth.json");
  truth.truth = nlohmann::json::parse(file);
  const RecordingWithCamera opened =
      OpenRecordingWithCamera(dir / "rm_depth_ahat.bin", dir / "calibration");
  const AhatCamera& camera = *opened.camera;
  sim::SceneRaycaster caster(truth.scenario.scene);
  const TruthHits hits =  // the scene is static: frame 0's truth holds for every frame
      CastTruthHits(truth.scenario.scene, caster, truth.truth.at("frames").at(0), camera);
  const int head = truth.scenario.patient->object;
  const int width = hits.object.width(), height = hits.object.height();
  std::vector<double> sum(static_cast<std::size_t>(width * height), 0.0);
  std::vector<int> count(sum.size(), 0);
  const std::size_t n = opened.recording->frame_count();
  for (std::size_t f = 0; f < n; ++f) {
    const AhatFrame frame = opened.recording->ReadFrame(f);
    for (int v = 0; v < height; ++v) {
      for (int u = 0; u < width; ++u) {
        const std::uint16_t r = frame.range_mm(u, v);
        if (r == 0 || r >= kAhatInvalidRange) continue;
        sum[static_cast<std::size_t>(v * width + u)] += r;
        ++count[static_cast<std::size_t>(v * width + u)];
      }
    }
    if (options.progress) options.progress(name + " phantom: average", f + 1, n);
  }
  std::vector<double> errors;
  for (int v = kPhantomMarginPx; v < height - kPhantomMarginPx; ++v) {
    for (int u = kPhantomMarginPx; u < width - kPhantomMarginPx; ++u) {
      const auto i = static_cast<std::size_t>(v * width + u);
      // Every frame valid, and the whole margin on the head (no silhouette, no sticker).
      if (count[i] != static_cast<int>(n) || hits.range_mm(u, v) <= 0.0f) continue;
      bool interior = true;
      for (int dv = -kPhantomMarginPx; dv <= kPhantomMarginPx && interior; ++dv)
        for (int du = -kPhantomMarginPx; du <= kPhantomMarginPx && interior; ++du)
          interior = hits.object(u + du, v + dv) == head;
      if (interior) errors.push_back(sum[i] / static_cast<double>(n) - hits.range_mm(u, v));
    }
  }
  if (errors.empty()) throw std::runtime_error(name + " phantom: no head pixel");
  return {Median(errors), Iqr(errors), errors.size()};
}

}  // namespace

void FidelityPhantoms(const FidelityOptions& options, FidelityResult& result) {
  const struct {
    const char* name;
    sim::Material material;
    double median_mm, iqr_mm;  // Table I "before"
  } phantoms[] = {{"photopolymer", sim::PhotopolymerMaterial(), 13.19, 7.31},
                  {"nylon", sim::NylonMaterial(), 7.64, 5.36}};
  nlohmann::ordered_json details = nlohmann::ordered_json::array();
  for (const auto& p : phantoms) {
    const PhantomFigures f = MeasurePhantom(options, p.material, p.name);
    result.rows.push_back(MakeFidelityRow("Table I, before",
                                          std::string(p.name) + " head: median depth error [mm]",
                                          kPhantomSource, p.median_mm, std::nullopt, f.median_mm));
    result.rows.push_back(MakeFidelityRow("Table I, before",
                                          std::string(p.name) + " head: IQR [mm]", kPhantomSource,
                                          p.iqr_mm, std::nullopt, f.iqr_mm));
    details.push_back({{"phantom", p.name},
                       {"pixels", f.pixels},
                       {"median_mm", f.median_mm},
                       {"iqr_mm", f.iqr_mm}});
  }
  result.details["phantoms"] = details;
}

}  // namespace tofnav
