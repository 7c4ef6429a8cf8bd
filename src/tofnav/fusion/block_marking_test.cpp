// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/fusion/block_marking.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "tofnav/fusion/tsdf_kernel.hpp"

namespace tofnav {
namespace {

TEST(BlockMarking, Avx2MarksTheSameBlocksAsScalar) {
  if (!CpuHasAvx2()) GTEST_SKIP() << "no AVX2 on this CPU";
  // A random walk of points (neighbours mostly share a box, as on a surface) with holes,
  // partly outside the ROI, over spans of every length modulo the eight lanes.
  constexpr int kDims[3] = {12, 10, 9};
  constexpr int kBase[3] = {-3, -2, 5};  // voxels -24 .. 71, -16 .. 63, 40 .. 111
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::size_t marked = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const float voxel_mm = trial % 2 == 0 ? 1.0f : 0.5f;
    const std::size_t n = 1 + static_cast<std::size_t>(trial * 37 % 301);
    std::vector<float> range(n);
    std::vector<std::array<float, 3>> points(n);
    std::array<float, 3> p{10.0f, 20.0f, 70.0f};  // in voxels
    for (std::size_t i = 0; i < n; ++i) {
      for (float& c : p) c += unit(rng) < 0.1f ? 20.0f * (unit(rng) - 0.5f) : unit(rng) - 0.5f;
      range[i] = unit(rng) < 0.15f ? 0.0f : 300.0f;
      // Unusable pixels hold stale points, which must not matter.
      // Some trials on a quarter-voxel grid: box faces then fall on voxel centres exactly.
      for (std::size_t a = 0; a < 3; ++a)
        points[i][a] = voxel_mm * (trial % 4 < 2 ? p[a] : std::round(4.0f * p[a]) / 4.0f);
    }
    std::vector<std::uint8_t> mask_a(kDims[0] * kDims[1] * kDims[2], 0), mask_b = mask_a;
    // Some trials with a truncation of more than a block (boxes of three blocks and more).
    const float truncation_mm = (trial % 5 == 4 ? 12.0f : 4.0f) * voxel_mm;
    BlockMarker marker{
        mask_a.data(),  kDims[0],      kDims[0] * kDims[1], {kBase[0], kBase[1], kBase[2]},
        {-20, -16, 45}, {60, 63, 100}, truncation_mm,       1.0f / voxel_mm};
    const std::size_t begin = static_cast<std::size_t>(trial % 3);
    MarkBlocks(marker, range.data(), points.data(), begin, n);
    marker.mask = mask_b.data();
    MarkBlocksAvx2(marker, range.data(), points.data(), begin, n);
    ASSERT_EQ(mask_a, mask_b) << trial;
    for (const std::uint8_t flag : mask_a) marked += flag;
  }
  EXPECT_GT(marked, 1000u);  // the walk marked many blocks
}

TEST(BlockMarking, MarksTheBlocksWithinOneTruncationOfThePoint) {
  // A point at voxel (20.5, 20.5, 20.5) with a 4-voxel truncation: its box reaches voxels
  // 17 .. 24, blocks 2 and 3 per axis, but block 3's voxels (24 ..) are 3.5 voxels away along
  // each axis: within the truncation across one face (3.5), not across an edge (4.95).
  constexpr int kDims = 5;
  for (const bool avx2 : {false, true}) {
    if (avx2 && !CpuHasAvx2()) continue;
    std::vector<std::uint8_t> mask(kDims * kDims * kDims, 0);
    const BlockMarker marker{mask.data(), kDims,        kDims * kDims, {0, 0, 0},
                             {0, 0, 0},   {39, 39, 39}, 4.0f,          1.0f};
    const float range[1] = {300.0f};
    const std::array<float, 3> point[1] = {{20.5f, 20.5f, 20.5f}};
    if (avx2) {
      MarkBlocksAvx2(marker, range, point, 0, 1);
    } else {
      MarkBlocks(marker, range, point, 0, 1);
    }
    const auto flag = [&](int x, int y, int z) { return mask[x + kDims * (y + kDims * z)]; };
    int marked = 0;
    for (const std::uint8_t f : mask) marked += f;
    EXPECT_EQ(marked, 4) << avx2;
    EXPECT_EQ(flag(2, 2, 2), 1);
    EXPECT_EQ(flag(3, 2, 2), 1);
    EXPECT_EQ(flag(2, 3, 2), 1);
    EXPECT_EQ(flag(2, 2, 3), 1);
  }
}

}  // namespace
}  // namespace tofnav
