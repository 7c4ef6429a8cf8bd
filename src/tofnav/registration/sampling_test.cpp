// SPDX-License-Identifier: BSD-3-Clause
// Voxel and farthest-point subsampling, and the nearest-sample lookup grid.
#include "tofnav/registration/sampling.hpp"

#include <gtest/gtest.h>

#include <random>
#include <set>
#include <tuple>

#include "tofnav/registration/nearest_sample_grid.hpp"

namespace tofnav {
namespace {

TEST(VoxelSubsample, KeepsThePointNearestEachVoxelMean) {
  // 4 x 4 points per 2 mm voxel (0.5 mm pitch, offset so no point lies on a voxel face).
  Points3d points;
  for (int x = 0; x < 8; ++x) {
    for (int y = 0; y < 8; ++y) points.emplace_back(0.25 + 0.5 * x, 0.25 + 0.5 * y, 0.1);
  }
  const std::vector<std::uint32_t> kept = VoxelSubsample(points, 2.0);
  ASSERT_EQ(kept.size(), 4u);  // 2 x 2 voxels
  std::set<std::tuple<int, int>> voxels;
  for (const std::uint32_t i : kept) {
    voxels.insert({static_cast<int>(points[i].x() / 2.0), static_cast<int>(points[i].y() / 2.0)});
    // The voxel mean is (1.0, 1.0) + corner; its nearest points are 0.25 mm away per axis.
    const Eigen::Vector3d mean(std::floor(points[i].x() / 2.0) * 2.0 + 1.0,
                               std::floor(points[i].y() / 2.0) * 2.0 + 1.0, 0.1);
    EXPECT_NEAR((points[i] - mean).norm(), std::sqrt(2.0) * 0.25, 1e-12);
  }
  EXPECT_EQ(voxels.size(), 4u);
  EXPECT_TRUE(std::is_sorted(kept.begin(), kept.end()));
  EXPECT_THROW(VoxelSubsample(points, 0.0), std::invalid_argument);
}

TEST(FarthestPointSample, TakesTheEndsThenTheMiddle) {
  Points3d line;
  for (int i = 0; i <= 100; ++i) line.emplace_back(i, 0.0, 0.0);
  line.emplace_back(100.5, 0.0, 0.0);  // breaks the tie: farthest from the centroid
  const std::vector<std::uint32_t> order = FarthestPointSample(line, 3);
  ASSERT_EQ(order.size(), 3u);
  EXPECT_EQ(line[order[0]].x(), 0.0);  // centroid is right of 50, so 0 is farthest
  EXPECT_EQ(line[order[1]].x(), 100.5);
  EXPECT_NEAR(line[order[2]].x(), 50.0, 0.5);
  EXPECT_EQ(FarthestPointSample(line, 1000).size(), line.size());
}

TEST(NearestSampleGrid, FindsASampleAtMostOneCellDiagonalFartherThanTheNearest) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-30.0, 30.0);
  Points3d samples;
  for (int i = 0; i < 400; ++i) samples.emplace_back(u(rng), u(rng), u(rng));
  constexpr double kCellMm = 2.0, kReachMm = 6.0;
  const NearestSampleGrid grid(samples, kCellMm, kReachMm);
  int checked = 0;
  for (int q = 0; q < 500; ++q) {
    const Eigen::Vector3d query(u(rng), u(rng), u(rng));
    double nearest_mm = 1e9;
    for (const Eigen::Vector3d& s : samples) nearest_mm = std::min(nearest_mm, (s - query).norm());
    if (nearest_mm > kReachMm) continue;
    const std::optional<std::uint32_t> found = grid.Lookup(query);
    ASSERT_TRUE(found.has_value());
    EXPECT_LE((samples[*found] - query).norm(), nearest_mm + std::sqrt(3.0) * kCellMm + 1e-9);
    ++checked;
  }
  EXPECT_GT(checked, 100);
  EXPECT_FALSE(grid.Lookup(Eigen::Vector3d(1e4, 0, 0)).has_value());  // outside the grid
}

}  // namespace
}  // namespace tofnav
