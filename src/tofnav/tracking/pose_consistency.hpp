// SPDX-License-Identifier: BSD-3-Clause
// Poses checked over time: the headframe is (nearly) still in `world`, so a pose of it that jumps
// relative to its neighbours is a tracking error (docs/reconstruction.md section 1.1).
#pragma once

#include <cstddef>
#include <optional>
#include <span>
#include <vector>

#include "tofnav/core/rigid3d.hpp"

namespace tofnav {

/// The temporal check of a (nearly) static tool's poses in `world`
/// (world_from_tool = world_from_rig * rig_from_ahat * ahat_from_tool).
struct PoseConsistencyOptions {
  /// Neighbours are the posed samples within this time of the sample, the sample itself left out
  /// [s]. 0.15 s is ~7 frames each side at 45 Hz: enough for a robust median, short enough that
  /// a moving patient or platform moves little (a symmetric window's median cancels a steady
  /// motion to first order; a turntable reversing at 8 deg/s is off by ~0.6 deg at the turn).
  double window_s = 0.15;
  std::size_t min_neighbours = 4;  // fewer: the sample is not judged (kUnchecked)
  /// A pose farther than this from the neighbours' median pose jumped [mm]: HoloLens 2 head
  /// tracking jitters ~0.5 mm and the tool's tracking ~0.2 mm RMS, so 3 mm is ~6 sigma of both.
  /// The check is for gross jumps (a wrong marker correspondence, a reflection taken for a
  /// marker); smaller offsets are the model check's (fusion/model_check.hpp).
  double max_translation_mm = 3.0;
  /// The same for rotation [rad]: SLAM ~0.1 deg and the tool's unfiltered rotation ~0.3 deg RMS
  /// (docs/tracking.md); 2 deg is ~6 sigma of the angle and above a turning platform's lag.
  double max_rotation_rad = 0.034906585039886591;
  /// A noisier sequence (head tracking jitters more in a poorly textured room) raises both
  /// thresholds to this many times the median deviation of all judged poses: 4 medians of a
  /// Maxwell-distributed deviation are ~6 sigma, so jitter alone is not a jump.
  double noise_factor = 4.0;
  void Check() const;  // throws PreconditionError naming the bad field
};

enum class PoseConsistency {
  kConsistent,  // within the thresholds of its neighbours' median
  kJump,        // farther: leave the frame out
  kUnchecked,   // no pose, or too few posed neighbours to judge
};

struct PoseConsistencyResult {
  PoseConsistency status = PoseConsistency::kUnchecked;
  double translation_mm = 0.0;  // distance to the neighbours' median pose (when judged)
  double rotation_rad = 0.0;
};

/// Judges every sample against the robust centre of its neighbours within options.window_s: the
/// component-wise median of their translations and the medoid of their rotations (the one whose
/// summed angle to the others is least). The neighbours' own jumps do not move that centre while
/// they are fewer than half. A jump is farther than max(max_translation_mm, noise_factor x the
/// median translation deviation of the sequence), or the same for rotation. `time_s` ascending, one
/// per pose; nullopt poses are not judged and are nobody's neighbour. Throws PreconditionError on
/// bad options or sizes.
std::vector<PoseConsistencyResult> CheckPoseConsistency(
    std::span<const std::optional<Rigid3d>> world_from_tool, std::span<const double> time_s,
    const PoseConsistencyOptions& options = {});

const char* ToString(PoseConsistency status);

/// The robust centre of a set of poses: the component-wise median of their translations and the
/// medoid of their rotations (the one whose summed angle to the others is least). Fewer than half
/// of them far off do not move it. Throws PreconditionError when `poses` is empty.
Rigid3d RobustPoseCentre(std::span<const Rigid3d* const> poses);

}  // namespace tofnav
