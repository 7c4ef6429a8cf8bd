// SPDX-License-Identifier: BSD-3-Clause
// Depth error per object against the simulator's truth range: labels by ray casting the truth.
#include "tofnav/evaluation/depth_evaluate.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <numbers>
#include <span>

#include "tofnav/correction/correct_range.hpp"
#include "tofnav/correction/identification_frame.hpp"
#include "tofnav/correction/range_normals.hpp"
#include "tofnav/evaluation/truth_hits.hpp"
#include "tofnav/io/file.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/sim/raycaster.hpp"

namespace tofnav {
namespace {

using Json = nlohmann::json;
constexpr std::size_t kTruthFrameBytes = 4u * kAhatPixels;
constexpr int kEdgeMarginPx = 2;      // pixels this close to another object or a marker: mixed
constexpr double kEdgeJumpMm = 10.0;  // truth range jump that marks a depth edge

// Interior pixels of an object: same label and no truth depth edge within the margin.
bool Interior(const Image<int>& labels, const Image<float>& truth, int u, int v) {
  const int label = labels(u, v);
  for (int dv = -kEdgeMarginPx; dv <= kEdgeMarginPx; ++dv) {
    for (int du = -kEdgeMarginPx; du <= kEdgeMarginPx; ++du) {
      if (!labels.Contains(u + du, v + dv) || labels(u + du, v + dv) != label) return false;
      if (std::abs(truth(u + du, v + dv) - truth(u, v)) > kEdgeJumpMm) return false;
    }
  }
  return true;
}

constexpr double kIncidenceBinDeg = 15.0;
constexpr double kRangeBinMm = 100.0;

// Medians of the errors whose key (range or incidence) falls in each `width` bin; NaN keys are
// left out.
std::vector<DepthErrorBin> ErrorBins(const ObjectDepthError& o, const std::vector<float>& key,
                                     double width) {
  std::map<long, std::pair<std::vector<float>, std::vector<float>>> bins;
  for (std::size_t i = 0; i < key.size(); ++i) {
    if (std::isnan(key[i])) continue;
    auto& [before, after] = bins[std::lround(std::floor(key[i] / width))];
    before.push_back(o.before_errors_mm[i]);
    if (!o.after_errors_mm.empty()) after.push_back(o.after_errors_mm[i]);
  }
  std::vector<DepthErrorBin> result;
  for (const auto& [bin, errors] : bins) {
    DepthErrorBin b{.from = static_cast<double>(bin) * width,
                    .to = static_cast<double>(bin + 1) * width,
                    .pixels = errors.first.size(),
                    .before_median_mm = Summarise(errors.first).median};
    if (!errors.second.empty()) b.after_median_mm = Summarise(errors.second).median;
    result.push_back(b);
  }
  return result;
}

}  // namespace

DepthEvaluation EvaluateDepthAgainstTruth(
    const AhatRecording& recording, const AhatCamera& camera,
    const std::filesystem::path& truth_dir, sim::Scenario scenario,
    const std::optional<DepthModelFile>& model, int max_frames,
    const std::function<void(std::size_t, std::size_t)>& progress) {
  const std::vector<std::uint8_t> bytes = ReadFileBytes(truth_dir / "truth.json");
  Json truth;
  try {
    truth = Json::parse(bytes.begin(), bytes.end());
  } catch (const Json::exception& e) {
    throw IoError(truth_dir / "truth.json", std::nullopt, std::string("not JSON: ") + e.what());
  }
  sim::SceneRaycaster caster(scenario.scene);
  const Json& truth_frames = truth.at("frames");
  const RandomAccessFile ranges(truth_dir / "truth_range_f32.bin");
  if (ranges.size() != truth_frames.size() * kTruthFrameBytes ||
      truth_frames.size() != recording.frame_count()) {
    throw IoError(truth_dir / "truth_range_f32.bin", std::nullopt,
                  "frame count differs from truth.json or the recording");
  }
  // The automatic head region (as identify segments): how much of each object it keeps.
  const SegmentationOptions roi_options = IdentificationSampling{}.segmentation;
  std::map<std::string, std::size_t> in_roi;
  std::string target;  // the object the head model is identified on (none: no patient)
  if (truth.contains("patient") && truth["patient"].contains("object")) {
    target = truth["patient"]["object"].get<std::string>();
  }
  CorrectRangeOptions correct_options;
  correct_options.roi_only = false;
  if (model && model->marker_range) correct_options.marker_model = *model->marker_range;

  std::map<std::string, ObjectDepthError> objects;
  const std::vector<int> picked = EvenSubsample(static_cast<int>(truth_frames.size()), max_frames);
  for (std::size_t n = 0; n < picked.size(); ++n) {
    const auto i = static_cast<std::size_t>(picked[n]);
    const AhatFrame frame = recording.ReadFrame(i);
    Image<float> truth_range(kAhatWidth, kAhatHeight);
    ranges.ReadAt(i * kTruthFrameBytes,
                  std::span(reinterpret_cast<std::uint8_t*>(truth_range.data()), kTruthFrameBytes),
                  "a truth range frame (float32 little-endian)");
    const Image<int> labels = CastTruthHits(scenario.scene, caster, truth_frames[i], camera).object;
    const FrameSegmentation roi = SegmentFrame(frame, camera, roi_options);
    const RangeNormals true_normals = ComputeRangeNormals(truth_range, camera);
    std::optional<Image<float>> corrected;
    if (model) corrected = CorrectRangeImage(frame, camera, model->model, correct_options);
    for (int v = 0; v < kAhatHeight; ++v) {
      for (int u = 0; u < kAhatWidth; ++u) {
        const int label = labels(u, v);
        const std::uint16_t measured = frame.range_mm(u, v);
        if (label < 0 || truth_range(u, v) <= 0.0f || measured == 0) continue;
        if (!Interior(labels, truth_range, u, v)) continue;
        if (corrected && (*corrected)(u, v) <= 0.0f) continue;  // dropped: not in either column
        const std::string& name = scenario.scene.objects[static_cast<std::size_t>(label)].name;
        ObjectDepthError& o = objects[name];
        if (roi.labels(u, v) == static_cast<std::uint8_t>(PixelClass::kHead)) ++in_roi[name];
        o.before_errors_mm.push_back(static_cast<float>(measured) - truth_range(u, v));
        if (corrected) o.after_errors_mm.push_back((*corrected)(u, v) - truth_range(u, v));
        o.true_range_mm.push_back(truth_range(u, v));
        o.true_incidence_deg.push_back(
            true_normals.normal(u, v).isZero()
                ? std::numeric_limits<float>::quiet_NaN()
                : static_cast<float>(true_normals.incidence_rad(u, v) * 180.0 / std::numbers::pi));
      }
    }
    if (progress) progress(n + 1, picked.size());
  }
  DepthEvaluation result;
  result.frames = picked.size();
  result.target_object = target;
  for (auto& [name, o] : objects) {
    o.name = name;
    o.before_mm = Summarise(o.before_errors_mm);
    o.by_incidence_deg = ErrorBins(o, o.true_incidence_deg, kIncidenceBinDeg);
    o.by_range_mm = ErrorBins(o, o.true_range_mm, kRangeBinMm);
    o.role = target.empty() ? "object" : name == target ? "target" : "other";
    o.head_region_percent = o.before_mm.count > 0 ? 100.0 * static_cast<double>(in_roi[name]) /
                                                        static_cast<double>(o.before_mm.count)
                                                  : 0.0;
    if (model) {
      o.after_mm = Summarise(o.after_errors_mm);
      o.reduction_percent =
          o.before_mm.median != 0.0
              ? 100.0 * (1.0 - std::abs(o.after_mm->median) / std::abs(o.before_mm.median))
              : 0.0;
    }
    result.objects.push_back(std::move(o));
  }
  return result;
}

nlohmann::json DepthErrorBinsJson(const std::vector<DepthErrorBin>& bins, const std::string& unit) {
  Json rows = Json::array();
  for (const DepthErrorBin& b : bins) {
    Json row{{"from_" + unit, b.from},
             {"to_" + unit, b.to},
             {"pixels", b.pixels},
             {"before_median_mm", b.before_median_mm}};
    if (b.after_median_mm) row["after_median_mm"] = *b.after_median_mm;
    rows.push_back(std::move(row));
  }
  return rows;
}

}  // namespace tofnav
