// SPDX-License-Identifier: BSD-3-Clause
// Deterministic point subsampling for registration: voxel grid and farthest-point sampling.
#pragma once

#include <cstdint>
#include <vector>

#include "tofnav/core/point_cloud.hpp"

namespace tofnav {

/// One point per occupied cubic voxel of edge `voxel_mm`: the point nearest the mean of the
/// voxel's points. Returns indices into `points`, in increasing order (independent of threads).
std::vector<std::uint32_t> VoxelSubsample(const Points3d& points, double voxel_mm);

/// `count` indices of `points` (all of them when there are fewer), spread by farthest-point
/// sampling that starts at the point farthest from the centroid. Returns them in sampling order.
std::vector<std::uint32_t> FarthestPointSample(const Points3d& points, std::size_t count);

/// Indices of `points` ordered along a Morton (Z-order) curve over cells of `cell_mm`, so that
/// consecutive points are near each other (cache-friendly KD-tree queries). Ties keep index order.
std::vector<std::uint32_t> SpatialOrder(const Points3d& points, double cell_mm);

/// points[indices[i]] for every i.
Points3d Gather(const Points3d& points, const std::vector<std::uint32_t>& indices);

}  // namespace tofnav
