// SPDX-License-Identifier: BSD-3-Clause
// Beyond the paper: the model variants compared on held-out blocks of frames.
#include <cstddef>
#include <stdexcept>

#include "tofnav/correction/identification.hpp"

namespace tofnav {
namespace {

template <typename T>
std::vector<T> WithoutBlock(std::span<const T> items, std::size_t lo, std::size_t hi) {
  std::vector<T> out(items.begin(), items.begin() + static_cast<std::ptrdiff_t>(lo));
  out.insert(out.end(), items.begin() + static_cast<std::ptrdiff_t>(hi), items.end());
  return out;
}

}  // namespace

std::vector<DepthErrorModel> DefaultModelCandidates() {
  std::vector<DepthErrorModel> out(4);
  out[1].angle_term = AngleTerm::kThetaSquared;
  out[2].angle_term = AngleTerm::kOneMinusCos;
  out[3].use_intensity = true;
  out.push_back(IntensityFormModel());
  return out;
}

std::vector<std::pair<std::string, double>> CrossValidateModels(
    std::span<const IdentificationFrame> frames, const CorrectnessTarget* target,
    std::span<const DepthErrorModel> candidates, int folds, const IdentificationOptions& options) {
  if (folds < 2 || static_cast<std::size_t>(folds) > frames.size()) {
    throw std::invalid_argument("CrossValidateModels: need 2 <= folds <= frames");
  }
  IdentificationOptions plain = options;
  plain.huber_scale_mm = 0.0;
  std::vector<std::pair<std::string, double>> out;
  for (const DepthErrorModel& candidate : candidates) {
    double sum = 0.0;
    int count = 0;
    for (int fold = 0; fold < folds; ++fold) {
      const std::size_t lo =
          frames.size() * static_cast<std::size_t>(fold) / static_cast<std::size_t>(folds);
      const std::size_t hi =
          frames.size() * static_cast<std::size_t>(fold + 1) / static_cast<std::size_t>(folds);
      const std::vector<IdentificationFrame> train = WithoutBlock(frames, lo, hi);
      CorrectnessTarget train_target;
      const CorrectnessTarget* train_target_ptr = nullptr;
      if (target && target->skin_in_image) {
        train_target.skin_in_image = target->skin_in_image;
        train_target.image_from_ahat = WithoutBlock(std::span(target->image_from_ahat), lo, hi);
        train_target_ptr = &train_target;
      }
      const DepthErrorModel fitted =
          IdentifyDepthModel(train, train_target_ptr, candidate, options);
      const IdentificationCost held =
          EvaluateIdentificationCost(frames.subspan(lo, hi - lo), nullptr, fitted, plain);
      for (const FrameResidual& r : held.frames) {
        if (r.err_s_mm < 0.0) continue;
        sum += r.err_s_mm * r.err_s_mm;
        ++count;
      }
    }
    out.emplace_back(candidate.Name(), count > 0 ? sum / count : 0.0);
  }
  return out;
}

}  // namespace tofnav
