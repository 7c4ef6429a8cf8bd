// SPDX-License-Identifier: BSD-3-Clause
// Poses checked over time as they arrive (navigate): a headframe's world pose that jumps away
// from its last accepted poses is left out, and a held pose is their mean (docs/navigation.md
// section 1.2).
#pragma once

#include <deque>
#include <optional>
#include <utility>

#include "tofnav/core/rigid3d.hpp"
#include "tofnav/tracking/pose_consistency.hpp"

namespace tofnav {

struct PoseJumpGuardOptions {
  /// Thresholds as in the recording's check (window_s is the trailing window here: the accepted
  /// poses of the last 2 x window_s, ~13 frames at 45 Hz, so the causal centre has as many
  /// neighbours as the symmetric one).
  PoseConsistencyOptions consistency;
  /// This many jumps in a row are a real move (the headframe was bumped, the patient turned):
  /// the history restarts from the newest pose. 5 frames is 0.11 s at 45 Hz.
  int max_jumps_in_a_row = 5;
  /// The noise estimate (for noise_factor) is the median deviation of the last this many
  /// judged poses.
  int noise_history = 200;
  void Check() const;  // throws PreconditionError naming the bad field
};

/// The causal form of CheckPoseConsistency for one (nearly) static tool, fed world_from_tool in
/// time order. Single-threaded.
class PoseJumpGuard {
 public:
  explicit PoseJumpGuard(const PoseJumpGuardOptions& options = {});

  /// Judges the pose against the robust centre (RobustPoseCentre) of the poses accepted in the
  /// trailing window; kConsistent and kUnchecked poses are accepted (kept as neighbours), kJump
  /// poses are not, until max_jumps_in_a_row of them restart the history (that pose: kUnchecked).
  PoseConsistencyResult Judge(const Rigid3d& world_from_tool, double time_s);
  /// The mean of the accepted poses of the last `span_s` up to `time_s` (translations averaged,
  /// rotations by their normalised quaternion mean): the held pose, with the per-frame tracking
  /// and head-tracking noise averaged out. nullopt when none is that recent.
  std::optional<Rigid3d> Mean(double time_s, double span_s) const;
  int jumps() const { return jumps_total_; }
  int restarts() const { return restarts_; }
  void Reset();

 private:
  PoseJumpGuardOptions options_;
  std::deque<std::pair<double, Rigid3d>> accepted_;  // (time, world_from_tool), newest last
  std::deque<double> deviations_mm_, deviations_rad_;
  int jumps_in_a_row_ = 0;
  int jumps_total_ = 0;
  int restarts_ = 0;
};

}  // namespace tofnav
