// SPDX-License-Identifier: BSD-3-Clause
// Reading the fused model back: voxels and trilinear samples of a TsdfVolume in `tool`.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <limits>
#include <optional>

#include "tofnav/fusion/tsdf_volume.hpp"

namespace tofnav {

/// The signed distance at a point (trilinear over the eight voxels around it) and its gradient.
struct TsdfSample {
  double distance_mm = 0.0;  // along the viewing rays, + in front of the surface, truncated
  Eigen::Vector3d gradient = Eigen::Vector3d::Zero();  // d distance / d point (dimensionless)
};

/// Voxel reads with the last block remembered (neighbouring reads mostly share a block). One per
/// thread: it is not thread-safe; the volume must outlive it and not change meanwhile.
class TsdfReader {
 public:
  explicit TsdfReader(const TsdfVolume& volume) : volume_(volume) {}

  /// Voxel with global index `index` when its weight is at least `min_weight` (> 0).
  std::optional<TsdfVoxel> Voxel(const Eigen::Vector3i& index, double min_weight);
  /// The voxel nearest to a point in `tool` [mm], as Voxel().
  std::optional<TsdfVoxel> NearestVoxel(const Eigen::Vector3d& point_in_tool, double min_weight);
  /// Trilinear sample at a point in `tool` [mm]; nullopt when any of the eight voxels around it
  /// weighs less than `min_weight` (unobserved or not observed often enough).
  std::optional<TsdfSample> Sample(const Eigen::Vector3d& point_in_tool, double min_weight);

 private:
  const TsdfVolume& volume_;
  Eigen::Vector3i cached_key_ =
      Eigen::Vector3i::Constant(std::numeric_limits<int>::max());  // matches no key
  std::optional<std::size_t> cached_block_;
};

}  // namespace tofnav
