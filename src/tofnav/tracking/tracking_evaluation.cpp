// SPDX-License-Identifier: BSD-3-Clause
// Pose errors, tracked fraction, wrong identities, static jitter and marker range bias.
#include "tofnav/tracking/tracking_evaluation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <stdexcept>

#include "tofnav/core/sampling_error.hpp"
#include "tofnav/core/units.hpp"

namespace tofnav {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

PoseErrorStats Stats(const std::vector<double>& mm, const std::vector<double>& deg) {
  const bool enough = mm.size() >= 4;
  return {Summarise(mm), Summarise(deg), enough ? RmsStandardError(mm) : kNan,
          enough ? RmsStandardError(deg) : kNan};
}

// Pooled sqrt(trace(covariance)) of positions over runs: sum |p - mean_run|^2 / sum n_run.
struct JitterSum {
  double squared = 0.0;
  int n = 0;
  void AddRun(const std::vector<Eigen::Vector3d>& run) {
    if (run.empty()) return;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& p : run) mean += p;
    mean /= static_cast<double>(run.size());
    for (const Eigen::Vector3d& p : run) squared += (p - mean).squaredNorm();
    n += static_cast<int>(run.size());
  }
  std::optional<double> Value() const {
    if (n == 0) return std::nullopt;
    return std::sqrt(squared / n);
  }
};

}  // namespace

void TrackingEvaluationOptions::Check() const {
  if (!(wrong_translation_mm > 0.0)) {
    throw std::invalid_argument("TrackingEvaluationOptions::wrong_translation_mm must be > 0");
  }
  if (!(wrong_rotation_rad > 0.0)) {
    throw std::invalid_argument("TrackingEvaluationOptions::wrong_rotation_rad must be > 0");
  }
  if (!(static_translation_mm >= 0.0) || !(static_rotation_rad >= 0.0)) {
    throw std::invalid_argument("TrackingEvaluationOptions static thresholds must be >= 0");
  }
  if (jitter_warmup_frames < 0 || min_static_frames < 2) {
    throw std::invalid_argument(
        "TrackingEvaluationOptions: jitter_warmup_frames >= 0, min_static_frames >= 2");
  }
  if (!(settled_rotation_sd_rad > 0.0)) {
    throw std::invalid_argument("TrackingEvaluationOptions::settled_rotation_sd_rad must be > 0");
  }
  if (!(range_bin_mm > 0.0)) {
    throw std::invalid_argument("TrackingEvaluationOptions::range_bin_mm must be > 0");
  }
}

bool TrackingEvaluationOptions::IsWrongIdentity(const Rigid3d& measured,
                                                const Rigid3d& truth) const {
  return TranslationDistanceMm(measured, truth) > wrong_translation_mm ||
         RotationDistanceRad(measured, truth) > wrong_rotation_rad;
}

ToolEvaluation EvaluateToolTracking(std::span<const ToolEvaluationFrame> frames,
                                    std::span<const Eigen::Vector3d> markers_in_tool,
                                    const TrackingEvaluationOptions& options) {
  options.Check();
  ToolEvaluation e;
  e.frames = static_cast<int>(frames.size());
  std::vector<double> raw_mm, raw_deg, filtered_mm, filtered_deg, visible_mm, visible_deg;
  std::vector<double> visible_filtered_mm, visible_filtered_deg, settled_mm, settled_deg;
  std::map<long, std::pair<double, int>> bins;  // bin index -> (sum of bias, count)
  JitterSum raw_jitter, filtered_jitter;
  std::vector<Eigen::Vector3d> raw_run, filtered_run;
  int run_length = 0;  // frames in the current static run
  const auto close_run = [&] {
    const auto keep = [&](std::vector<Eigen::Vector3d>& run, JitterSum& sum) {
      if (static_cast<int>(run.size()) >= options.min_static_frames) sum.AddRun(run);
      run.clear();
    };
    if (static_cast<int>(raw_run.size()) >= options.min_static_frames) {
      e.static_frames += static_cast<int>(raw_run.size());
    }
    keep(raw_run, raw_jitter);
    keep(filtered_run, filtered_jitter);
    run_length = 0;
  };
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const ToolEvaluationFrame& f = frames[i];
    const bool still =
        i > 0 &&
        TranslationDistanceMm(f.true_ahat_from_tool, frames[i - 1].true_ahat_from_tool) <=
            options.static_translation_mm &&
        RotationDistanceRad(f.true_ahat_from_tool, frames[i - 1].true_ahat_from_tool) <=
            options.static_rotation_rad;
    if (!still) close_run();
    ++run_length;
    if (f.fully_visible) ++e.fully_visible_frames;
    if (!f.raw) continue;
    ++e.posed_frames;
    if (options.IsWrongIdentity(*f.raw, f.true_ahat_from_tool)) {
      ++e.wrong_identities;
      continue;
    }
    const double mm = TranslationDistanceMm(*f.raw, f.true_ahat_from_tool);
    const double rad = RotationDistanceRad(*f.raw, f.true_ahat_from_tool);
    if (f.fully_visible) {
      ++e.tracked_fully_visible;
      visible_mm.push_back(mm);
      visible_deg.push_back(rad * kRadToDeg);
    }
    raw_mm.push_back(mm);
    raw_deg.push_back(rad * kRadToDeg);
    for (const Eigen::Vector3d& m : markers_in_tool) {
      const double true_range_mm = (f.true_ahat_from_tool * m).norm();
      auto& bin = bins[std::lround(std::floor(true_range_mm / options.range_bin_mm))];
      bin.first += (*f.raw * m).norm() - true_range_mm;
      ++bin.second;
    }
    if (run_length > options.jitter_warmup_frames) raw_run.push_back(f.raw->translation);
    if (f.filtered) {
      filtered_mm.push_back(TranslationDistanceMm(*f.filtered, f.true_ahat_from_tool));
      filtered_deg.push_back(RotationDistanceRad(*f.filtered, f.true_ahat_from_tool) * kRadToDeg);
      const bool settling = IsSettling(f.filtered_rotation_sd_rad, options.settled_rotation_sd_rad);
      e.settling_frames += settling ? 1 : 0;
      if (f.fully_visible) {
        visible_filtered_mm.push_back(filtered_mm.back());
        visible_filtered_deg.push_back(filtered_deg.back());
        if (!settling) {
          settled_mm.push_back(filtered_mm.back());
          settled_deg.push_back(filtered_deg.back());
        }
      }
      if (run_length > options.jitter_warmup_frames)
        filtered_run.push_back(f.filtered->translation);
    }
  }
  close_run();
  e.tracked_fraction = e.fully_visible_frames > 0
                           ? static_cast<double>(e.tracked_fully_visible) / e.fully_visible_frames
                           : 0.0;
  e.raw = Stats(raw_mm, raw_deg);
  e.filtered = Stats(filtered_mm, filtered_deg);
  e.raw_fully_visible = Stats(visible_mm, visible_deg);
  e.filtered_fully_visible = Stats(visible_filtered_mm, visible_filtered_deg);
  e.filtered_settled_fully_visible = Stats(settled_mm, settled_deg);
  e.jitter_raw_mm = raw_jitter.Value();
  e.jitter_filtered_mm = filtered_jitter.Value();
  for (const auto& [index, sum] : bins) {
    const double from = static_cast<double>(index) * options.range_bin_mm;
    e.range_bias.push_back({from, from + options.range_bin_mm, sum.first / sum.second, sum.second});
  }
  return e;
}

}  // namespace tofnav
