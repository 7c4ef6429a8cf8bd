// SPDX-License-Identifier: BSD-3-Clause
// The causal temporal pose check and the held pose's mean.
#include "tofnav/tracking/pose_jump_guard.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "tofnav/core/require.hpp"

namespace tofnav {
namespace {

double MedianOfCopy(const std::deque<double>& values) {
  std::vector<double> v(values.begin(), values.end());
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;  // the upper median: a threshold, not an estimate
}

}  // namespace

void PoseJumpGuardOptions::Check() const {
  consistency.Check();
  Require(max_jumps_in_a_row >= 1, "PoseJumpGuardOptions::max_jumps_in_a_row must be >= 1");
  Require(noise_history >= 1, "PoseJumpGuardOptions::noise_history must be >= 1");
}

PoseJumpGuard::PoseJumpGuard(const PoseJumpGuardOptions& options) : options_(options) {
  options_.Check();
}

void PoseJumpGuard::Reset() {
  accepted_.clear();
  deviations_mm_.clear();
  deviations_rad_.clear();
  jumps_in_a_row_ = 0;
}

PoseConsistencyResult PoseJumpGuard::Judge(const Rigid3d& world_from_tool, double time_s) {
  const PoseConsistencyOptions& c = options_.consistency;
  // Time going backwards (a restarted stream): start over.
  if (!accepted_.empty() && time_s < accepted_.back().first) Reset();
  while (!accepted_.empty() && time_s - accepted_.front().first > 2.0 * c.window_s) {
    accepted_.pop_front();
  }
  PoseConsistencyResult result;
  if (accepted_.size() >= c.min_neighbours) {
    std::vector<const Rigid3d*> neighbours;
    neighbours.reserve(accepted_.size());
    for (const auto& [t, pose] : accepted_) neighbours.push_back(&pose);
    const Rigid3d centre = RobustPoseCentre(neighbours);
    result.translation_mm = TranslationDistanceMm(world_from_tool, centre);
    result.rotation_rad = RotationDistanceRad(world_from_tool, centre);
    double max_mm = c.max_translation_mm, max_rad = c.max_rotation_rad;
    if (!deviations_mm_.empty()) {
      max_mm = std::max(max_mm, c.noise_factor * MedianOfCopy(deviations_mm_));
      max_rad = std::max(max_rad, c.noise_factor * MedianOfCopy(deviations_rad_));
    }
    const bool jump = result.translation_mm > max_mm || result.rotation_rad > max_rad;
    result.status = jump ? PoseConsistency::kJump : PoseConsistency::kConsistent;
    deviations_mm_.push_back(result.translation_mm);
    deviations_rad_.push_back(result.rotation_rad);
    if (static_cast<int>(deviations_mm_.size()) > options_.noise_history) {
      deviations_mm_.pop_front();
      deviations_rad_.pop_front();
    }
  }
  if (result.status == PoseConsistency::kJump) {
    ++jumps_total_;
    if (++jumps_in_a_row_ < options_.max_jumps_in_a_row) return result;
    // A real move: the old neighbours describe where the tool was, not where it is.
    accepted_.clear();
    ++restarts_;
    result.status = PoseConsistency::kUnchecked;
  }
  jumps_in_a_row_ = 0;
  accepted_.emplace_back(time_s, world_from_tool);
  return result;
}

std::optional<Rigid3d> PoseJumpGuard::Mean(double time_s, double span_s) const {
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  Eigen::Vector4d quaternion = Eigen::Vector4d::Zero();
  int n = 0;
  for (const auto& [t, pose] : accepted_) {
    if (t > time_s || time_s - t > span_s) continue;
    translation += pose.translation;
    Eigen::Vector4d q = pose.rotation.coeffs();
    if (n > 0 && q.dot(quaternion) < 0.0) q = -q;  // one hemisphere
    quaternion += q;
    ++n;
  }
  if (n == 0) return std::nullopt;
  Eigen::Quaterniond mean(quaternion / static_cast<double>(n));
  mean.normalize();
  return Rigid3d(mean, translation / static_cast<double>(n));
}

}  // namespace tofnav
