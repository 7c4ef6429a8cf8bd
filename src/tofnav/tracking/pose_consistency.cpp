// SPDX-License-Identifier: BSD-3-Clause
// Poses checked over time against the robust centre of their neighbours.
#include "tofnav/tracking/pose_consistency.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "tofnav/core/require.hpp"

namespace tofnav {
namespace {

double MedianOf(std::vector<double>& values) {
  const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  if (values.size() % 2 == 1) return *mid;
  return 0.5 * (*mid + *std::max_element(values.begin(), mid));
}

}  // namespace

Rigid3d RobustPoseCentre(std::span<const Rigid3d* const> poses) {
  Require(!poses.empty(), "RobustPoseCentre: no poses");
  Eigen::Vector3d translation;
  std::vector<double> values(poses.size());
  for (int axis = 0; axis < 3; ++axis) {
    for (std::size_t i = 0; i < poses.size(); ++i) values[i] = poses[i]->translation[axis];
    translation[axis] = MedianOf(values);
  }
  std::size_t best = 0;
  double best_sum = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < poses.size(); ++i) {
    double sum = 0.0;
    for (const Rigid3d* other : poses) sum += poses[i]->rotation.angularDistance(other->rotation);
    if (sum < best_sum) best_sum = sum, best = i;
  }
  return {poses[best]->rotation, translation};
}

void PoseConsistencyOptions::Check() const {
  Require(std::isfinite(window_s) && window_s > 0.0,
          "PoseConsistencyOptions::window_s must be > 0");
  Require(min_neighbours >= 2, "PoseConsistencyOptions::min_neighbours must be >= 2");
  Require(std::isfinite(max_translation_mm) && max_translation_mm > 0.0,
          "PoseConsistencyOptions::max_translation_mm must be > 0");
  Require(std::isfinite(max_rotation_rad) && max_rotation_rad > 0.0,
          "PoseConsistencyOptions::max_rotation_rad must be > 0");
  Require(std::isfinite(noise_factor) && noise_factor >= 0.0,
          "PoseConsistencyOptions::noise_factor must be >= 0");
}

std::vector<PoseConsistencyResult> CheckPoseConsistency(
    std::span<const std::optional<Rigid3d>> world_from_tool, std::span<const double> time_s,
    const PoseConsistencyOptions& options) {
  options.Check();
  Require(world_from_tool.size() == time_s.size(),
          "CheckPoseConsistency: one time per pose is required");
  const std::size_t n = world_from_tool.size();
  std::vector<PoseConsistencyResult> results(n);
  std::size_t lo = 0, hi = 0;  // the window [lo, hi) around sample i
  std::vector<const Rigid3d*> neighbours;
  for (std::size_t i = 0; i < n; ++i) {
    while (lo < i && time_s[i] - time_s[lo] > options.window_s) ++lo;
    while (hi < n && time_s[hi] - time_s[i] <= options.window_s) ++hi;
    if (!world_from_tool[i]) continue;
    neighbours.clear();
    for (std::size_t j = lo; j < hi; ++j) {
      if (j != i && world_from_tool[j]) neighbours.push_back(&*world_from_tool[j]);
    }
    if (neighbours.size() < options.min_neighbours) continue;
    const Rigid3d centre = RobustPoseCentre(neighbours);
    PoseConsistencyResult& r = results[i];
    r.translation_mm = TranslationDistanceMm(*world_from_tool[i], centre);
    r.rotation_rad = RotationDistanceRad(*world_from_tool[i], centre);
    r.status = PoseConsistency::kConsistent;
  }
  std::vector<double> translations, rotations;
  for (const PoseConsistencyResult& r : results) {
    if (r.status == PoseConsistency::kUnchecked) continue;
    translations.push_back(r.translation_mm);
    rotations.push_back(r.rotation_rad);
  }
  if (translations.empty()) return results;
  const double max_mm =
      std::max(options.max_translation_mm, options.noise_factor * MedianOf(translations));
  const double max_rad =
      std::max(options.max_rotation_rad, options.noise_factor * MedianOf(rotations));
  for (PoseConsistencyResult& r : results) {
    if (r.status == PoseConsistency::kConsistent &&
        (r.translation_mm > max_mm || r.rotation_rad > max_rad)) {
      r.status = PoseConsistency::kJump;
    }
  }
  return results;
}

const char* ToString(PoseConsistency status) {
  switch (status) {
    case PoseConsistency::kConsistent:
      return "consistent";
    case PoseConsistency::kJump:
      return "pose_jump";
    case PoseConsistency::kUnchecked:
      return "unchecked";
  }
  return "unknown";
}

}  // namespace tofnav
