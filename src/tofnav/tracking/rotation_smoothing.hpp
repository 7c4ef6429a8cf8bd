// SPDX-License-Identifier: BSD-3-Clause
// Offline smoothing of a (nearly) still tool's orientation in `world`: a local linear fit over
// time of the rotations of its neighbours (docs/reconstruction.md 1.1).
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <optional>
#include <span>
#include <vector>

#include "tofnav/core/rigid3d.hpp"

namespace tofnav {

struct RotationSmoothingOptions {
  /// Samples within this time of a sample take part in its fit [s]. The reference tool's raw
  /// orientation jitters ~0.3-0.6 deg RMS frame to frame while the SLAM pose that carries it
  /// into `world` jitters ~0.02-0.1 deg, so averaging n frames in `world` divides the first by
  /// about sqrt(n) (docs/reconstruction.md 1.1).
  double half_window_s = 0.5;
  /// Fewer samples in the window (the sample included): left as measured.
  std::size_t min_samples = 3;
  /// Samples farther than this from the window's first straight-line fit are left out of the
  /// second [rad]; a sample that far from its own window's line is left as measured (a jump: the
  /// temporal check's 2 deg, docs/reconstruction.md 1.1).
  double max_deviation_rad = 0.034906585039886591;
  void Check() const;  // throws PreconditionError naming the bad field
};

/// For every posed sample, the rotation at its time of a straight-line fit (rotation vector
/// against time, in the tangent space at the sample's own rotation) to the posed samples within
/// half_window_s, refitted without those beyond max_deviation_rad of the first fit: the mean for
/// a still tool, exact for one turning at a steady rate, and without the lag of a causal filter.
/// nullopt poses (none, or left out as a jump) are neither smoothed nor anybody's neighbour; a
/// sample with too few in its window gets nullopt, and so does one beyond max_deviation_rad of
/// its own window's line (a jump). `time_s` one per pose, finite, in any order; throws
/// PreconditionError on bad options, sizes or times.
std::vector<std::optional<Eigen::Quaterniond>> SmoothWorldRotations(
    std::span<const std::optional<Rigid3d>> world_from_tool, std::span<const double> time_s,
    const RotationSmoothingOptions& options = {});

/// The same for poses measured in the camera: every frame with both an ahat_from_tool and a
/// world_from_ahat (the headset's pose; nullopt also leaves a frame out, e.g. a pose jump) gets
/// its orientation smoothed as world_from_tool = world_from_ahat * ahat_from_tool and mapped
/// back through its own world_from_ahat; positions stay as measured (in `world` they carry the
/// headset's drift). Returns the number of frames smoothed. Sizes must agree.
std::size_t SmoothAhatRotations(std::span<std::optional<Rigid3d>> ahat_from_tool,
                                std::span<const std::optional<Rigid3d>> world_from_ahat,
                                std::span<const double> time_s,
                                const RotationSmoothingOptions& options = {});

}  // namespace tofnav
