// SPDX-License-Identifier: BSD-3-Clause
// Voxel-grid and farthest-point subsampling.
#include "tofnav/registration/sampling.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>
#include <utility>

#include "tofnav/core/require.hpp"

namespace tofnav {

std::vector<std::uint32_t> VoxelSubsample(const Points3d& points, double voxel_mm) {
  Require(voxel_mm > 0.0 && std::isfinite(voxel_mm), "VoxelSubsample: voxel_mm must be > 0");
  Require(points.size() < std::numeric_limits<std::uint32_t>::max(), "VoxelSubsample: too many");
  struct Keyed {
    Eigen::Vector3i cell;
    std::uint32_t index;
  };
  std::vector<Keyed> keyed;
  keyed.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d cell = (points[i] / voxel_mm).array().floor();
    // Cells beyond +-2^30 voxels cannot occur for a head; non-finite points are skipped.
    if (!cell.allFinite() || cell.cwiseAbs().maxCoeff() > 1e9) continue;
    keyed.push_back({cell.cast<int>(), static_cast<std::uint32_t>(i)});
  }
  const auto less = [](const Keyed& a, const Keyed& b) {
    return std::tie(a.cell.x(), a.cell.y(), a.cell.z(), a.index) <
           std::tie(b.cell.x(), b.cell.y(), b.cell.z(), b.index);
  };
  std::sort(keyed.begin(), keyed.end(), less);
  std::vector<std::uint32_t> chosen;
  for (std::size_t begin = 0; begin < keyed.size();) {
    std::size_t end = begin + 1;
    while (end < keyed.size() && keyed[end].cell == keyed[begin].cell) ++end;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (std::size_t i = begin; i < end; ++i) mean += points[keyed[i].index];
    mean /= static_cast<double>(end - begin);
    std::uint32_t best = keyed[begin].index;
    double best_sq = std::numeric_limits<double>::infinity();
    for (std::size_t i = begin; i < end; ++i) {
      const double d_sq = (points[keyed[i].index] - mean).squaredNorm();
      if (d_sq < best_sq) best_sq = d_sq, best = keyed[i].index;
    }
    chosen.push_back(best);
    begin = end;
  }
  std::sort(chosen.begin(), chosen.end());
  return chosen;
}

std::vector<std::uint32_t> FarthestPointSample(const Points3d& points, std::size_t count) {
  Require(points.size() < std::numeric_limits<std::uint32_t>::max(),
          "FarthestPointSample: too many");
  count = std::min(count, points.size());
  std::vector<std::uint32_t> chosen;
  if (count == 0) return chosen;
  chosen.reserve(count);
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) centroid += p;
  centroid /= static_cast<double>(points.size());
  std::vector<double> distance_sq(points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
    distance_sq[i] = (points[i] - centroid).squaredNorm();
  for (std::size_t k = 0; k < count; ++k) {
    const auto next = static_cast<std::uint32_t>(
        std::max_element(distance_sq.begin(), distance_sq.end()) - distance_sq.begin());
    chosen.push_back(next);
    if (k == 0)
      std::fill(distance_sq.begin(), distance_sq.end(), std::numeric_limits<double>::infinity());
    for (std::size_t i = 0; i < points.size(); ++i) {
      distance_sq[i] = std::min(distance_sq[i], (points[i] - points[next]).squaredNorm());
    }
  }
  return chosen;
}

namespace {

/// The low 21 bits of v spread to every third bit (Morton encoding).
std::uint64_t SpreadBits(std::uint64_t v) {
  v &= 0x1fffff;
  v = (v | v << 32) & 0x1f00000000ffff;
  v = (v | v << 16) & 0x1f0000ff0000ff;
  v = (v | v << 8) & 0x100f00f00f00f00f;
  v = (v | v << 4) & 0x10c30c30c30c30c3;
  v = (v | v << 2) & 0x1249249249249249;
  return v;
}

}  // namespace

std::vector<std::uint32_t> SpatialOrder(const Points3d& points, double cell_mm) {
  Require(cell_mm > 0.0, "SpatialOrder: cell_mm must be > 0");
  Require(points.size() < std::numeric_limits<std::uint32_t>::max(), "SpatialOrder: too many");
  Eigen::Vector3d low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  for (const Eigen::Vector3d& p : points) {
    if (p.allFinite()) low = low.cwiseMin(p);
  }
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    std::uint64_t key = 0;
    if (points[i].allFinite()) {
      for (int axis = 0; axis < 3; ++axis) {
        // Cells beyond 2^21 (20 km at 1 cm) share the last cell: order only, never correctness.
        const double cell = std::min((points[i](axis) - low(axis)) / cell_mm, 2097151.0);
        key |= SpreadBits(static_cast<std::uint64_t>(cell)) << axis;
      }
    }
    keyed[i] = {key, static_cast<std::uint32_t>(i)};
  }
  std::sort(keyed.begin(), keyed.end());
  std::vector<std::uint32_t> order(points.size());
  for (std::size_t i = 0; i < keyed.size(); ++i) order[i] = keyed[i].second;
  return order;
}

Points3d Gather(const Points3d& points, const std::vector<std::uint32_t>& indices) {
  Points3d out;
  out.reserve(indices.size());
  for (const std::uint32_t i : indices) out.push_back(points[i]);
  return out;
}

}  // namespace tofnav
