// SPDX-License-Identifier: BSD-3-Clause
// Fidelity, Table I "before" (paper Sec. IV-A): a head phantom static and facing the headset at
// about 300 mm, each pixel's range averaged over the frames, minus the true range; median and
// IQR over the head's interior pixels. The photopolymer and the nylon head; Table I "after" the
// same with each frame corrected by a given depth model first.
#include <cmath>
#include <fstream>

#include "tofnav/core/statistics.hpp"
#include "tofnav/correction/correct_range.hpp"
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

// Per pixel: the sum of one column's ranges over the frames and how many frames gave one.
struct RangeSums {
  std::vector<double> sum;
  std::vector<int> count;
  void Add(std::size_t i, double range_mm) {
    sum[i] += range_mm;
    ++count[i];
  }
};

// Median and IQR of the per-pixel mean error over the head's interior pixels that every frame
// measured (the whole margin on the head: no silhouette, no sticker).
PhantomFigures HeadFigures(const RangeSums& sums, const TruthHits& hits, int head, int frames,
                           const std::string& name) {
  const int width = hits.object.width(), height = hits.object.height();
  std::vector<double> errors;
  for (int v = kPhantomMarginPx; v < height - kPhantomMarginPx; ++v) {
    for (int u = kPhantomMarginPx; u < width - kPhantomMarginPx; ++u) {
      const auto i = static_cast<std::size_t>(v * width + u);
      if (sums.count[i] != frames || hits.range_mm(u, v) <= 0.0f) continue;
      bool interior = true;
      for (int dv = -kPhantomMarginPx; dv <= kPhantomMarginPx && interior; ++dv)
        for (int du = -kPhantomMarginPx; du <= kPhantomMarginPx && interior; ++du)
          interior = hits.object(u + du, v + dv) == head;
      if (interior) {
        errors.push_back(sums.sum[i] / static_cast<double>(frames) - hits.range_mm(u, v));
      }
    }
  }
  if (errors.empty()) throw std::runtime_error(name + " phantom: no head pixel");
  return {Median(errors), Iqr(errors), errors.size()};
}

struct PhantomResult {
  PhantomFigures before;
  /// With a model: after its correction, and before it on the same pixels (those its
  /// correction keeps in every frame).
  std::optional<PhantomFigures> after, before_kept;
};

// The head's per-pixel mean error over the frames of one facing-phantom simulation, before and
// (with `model`) after the model's correction of every frame.
PhantomResult MeasurePhantom(const FidelityOptions& options, const sim::Material& material,
                             const std::string& name, const DepthModelFile* model) {
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
  const auto pixels = static_cast<std::size_t>(width * height);
  RangeSums before{std::vector<double>(pixels, 0.0), std::vector<int>(pixels, 0)};
  RangeSums after = before, before_kept = before;
  CorrectRangeOptions correct_options;
  correct_options.roi_only = false;
  if (model && model->marker_range) correct_options.marker_model = *model->marker_range;
  const std::size_t n = opened.recording->frame_count();
  for (std::size_t f = 0; f < n; ++f) {
    const AhatFrame frame = opened.recording->ReadFrame(f);
    std::optional<Image<float>> corrected;
    if (model) corrected = CorrectRangeImage(frame, camera, model->model, correct_options);
    for (int v = 0; v < height; ++v) {
      for (int u = 0; u < width; ++u) {
        const std::uint16_t r = frame.range_mm(u, v);
        if (r == 0 || r >= kAhatInvalidRange) continue;
        const auto i = static_cast<std::size_t>(v * width + u);
        before.Add(i, r);
        if (corrected && (*corrected)(u, v) > 0.0f) {
          after.Add(i, (*corrected)(u, v));
          before_kept.Add(i, r);
        }
      }
    }
    if (options.progress) options.progress(name + " phantom: average", f + 1, n);
  }
  const int read = static_cast<int>(n);
  PhantomResult result{HeadFigures(before, hits, head, read, name), std::nullopt, std::nullopt};
  if (model) {
    result.after = HeadFigures(after, hits, head, read, name);
    result.before_kept = HeadFigures(before_kept, hits, head, read, name);
  }
  return result;
}

}  // namespace

void FidelityPhantoms(const FidelityOptions& options, FidelityResult& result) {
  const struct {
    const char* name;
    sim::Material material;
    double median_mm, iqr_mm;              // Table I "before"
    double after_median_mm, after_iqr_mm;  // Table I "after"
  } phantoms[] = {{"photopolymer", sim::PhotopolymerMaterial(), 13.19, 7.31, 0.89, 1.14},
                  {"nylon", sim::NylonMaterial(), 7.64, 5.36, 1.08, 1.41}};
  nlohmann::ordered_json details = nlohmann::ordered_json::array();
  for (const auto& p : phantoms) {
    const auto model = options.phantom_depth_models.find(p.name);
    const DepthModelFile* given =
        model == options.phantom_depth_models.end() ? nullptr : &model->second;
    const PhantomResult measured = MeasurePhantom(options, p.material, p.name, given);
    const PhantomFigures& f = measured.before;
    const std::optional<PhantomFigures>& after = measured.after;
    result.rows.push_back(MakeFidelityRow("Table I, before",
                                          std::string(p.name) + " head: median depth error [mm]",
                                          kPhantomSource, p.median_mm, std::nullopt, f.median_mm));
    result.rows.push_back(MakeFidelityRow("Table I, before",
                                          std::string(p.name) + " head: IQR [mm]", kPhantomSource,
                                          p.iqr_mm, std::nullopt, f.iqr_mm));
    nlohmann::ordered_json detail{{"phantom", p.name},
                                  {"pixels", f.pixels},
                                  {"median_mm", f.median_mm},
                                  {"iqr_mm", f.iqr_mm}};
    if (after) {
      const std::string label = std::string(p.name) + " head, the given model: ";
      result.rows.push_back(MakeFidelityRow("Table I, after", label + "median depth error [mm]",
                                            kPhantomSource, p.after_median_mm, std::nullopt,
                                            after->median_mm));
      result.rows.push_back(MakeFidelityRow("Table I, after", label + "IQR [mm]", kPhantomSource,
                                            p.after_iqr_mm, std::nullopt, after->iqr_mm));
      detail["after"] = {{"pixels", after->pixels},
                         {"median_mm", after->median_mm},
                         {"iqr_mm", after->iqr_mm},
                         {"before_median_mm", measured.before_kept->median_mm},
                         {"before_iqr_mm", measured.before_kept->iqr_mm}};
    }
    details.push_back(detail);
  }
  result.details["phantoms"] = details;
}

}  // namespace tofnav
