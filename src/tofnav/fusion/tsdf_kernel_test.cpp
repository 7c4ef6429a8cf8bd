// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/fusion/tsdf_kernel.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "tofnav/fusion/fusion_test_scenes.hpp"

namespace tofnav {
namespace {

TEST(TsdfKernel, Avx2RowMatchesScalarRowBitForBit) {
  if (!CpuHasAvx2()) GTEST_SKIP() << "no AVX2 on this CPU";
  // A random range image with holes and jumps, random rows around it, random prior values:
  // every branch of the row update (unseen, occluded, jump, truncated, weighted) is taken.
  constexpr int kWidth = 40, kHeight = 30;
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::vector<float> range(kWidth * kHeight), pixel_weight(kWidth * kHeight);
  for (std::size_t i = 0; i < range.size(); ++i) {
    range[i] = unit(rng) < 0.1f ? 0.0f : 300.0f + 20.0f * unit(rng);
    pixel_weight[i] = unit(rng) < 0.1f ? 0.0f : unit(rng);
  }
  const AhatCamera camera(SmallFisheyeCalibration(16));
  const PixelLookup lookup(camera);
  int compared = 0, updated = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const bool weighted = trial % 2 == 1, bilinear = trial % 4 < 2;
    const KernelInputs in{lookup.table(), range.data(), weighted ? pixel_weight.data() : nullptr,
                          kWidth,         kHeight,      4.0f,
                          0.25f,          10.0f,        20.0f};
    // Pixel positions stay inside the image over the row's eight voxels.
    const float u = 4.0f + 26.0f * unit(rng), v = 4.0f + 18.0f * unit(rng);
    KernelRow row{unit(rng), unit(rng), 290.0f + 30.0f * unit(rng), 0.8f * unit(rng),
                  0.3f * unit(rng), 1.0f - 2.0f * unit(rng), u, v, unit(rng) - 0.5f,
                  unit(rng) - 0.5f, trial % 5 == 0 ? 2 : 0, trial % 7 == 0 ? 5 : 8,
                  // Some rows partly beyond the occlusion cull (lanes skipped on both paths).
                  trial % 3 == 0 ? 295.0f + 25.0f * unit(rng) : INFINITY};
    std::array<float, 8> tsdf_a, weight_a;
    for (std::size_t k = 0; k < 8; ++k) {
      tsdf_a[k] = 2.0f * unit(rng) - 1.0f;
      weight_a[k] = unit(rng) < 0.3f ? 0.0f : 25.0f * unit(rng);
    }
    std::array<float, 8> tsdf_b = tsdf_a, weight_b = weight_a;
    const std::int64_t n_scalar =
        UpdateRow(in, row, true, bilinear, tsdf_a.data(), weight_a.data());
    const std::int64_t n_simd =
        UpdateInterpolatedRowAvx2(in, row, bilinear, tsdf_b.data(), weight_b.data());
    ASSERT_EQ(n_scalar, n_simd) << trial;
    ASSERT_EQ(std::memcmp(tsdf_a.data(), tsdf_b.data(), sizeof(tsdf_a)), 0) << trial;
    ASSERT_EQ(std::memcmp(weight_a.data(), weight_b.data(), sizeof(weight_a)), 0) << trial;
    updated += static_cast<int>(n_scalar);
    ++compared;
  }
  EXPECT_EQ(compared, 400);
  EXPECT_GT(updated, 300);  // enough voxels took the update path, not only the skips
}

TEST(TsdfKernel, Avx2CornerProjectionMatchesScalarBitForBit) {
  if (!CpuHasAvx2()) GTEST_SKIP() << "no AVX2 on this CPU";
  // Random blocks in front of a small fisheye, some partly outside its view: both paths must
  // agree on which blocks are seen and on every corner's pixel position.
  const AhatCamera camera(SmallFisheyeCalibration(32));
  const PixelLookup lookup(camera);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  int seen = 0, unseen = 0;
  for (int trial = 0; trial < 500; ++trial) {
    const float origin[3] = {200.0f * unit(rng), 200.0f * unit(rng), 150.0f + 100.0f * unit(rng)};
    float steps[9];
    for (float& s : steps) s = unit(rng);
    std::array<float, 9> u_a{}, v_a{}, u_b{}, v_b{};
    const bool a = ProjectCorners(lookup.table(), origin, steps, u_a.data(), v_a.data());
    const bool b = ProjectCornersAvx2(lookup.table(), origin, steps, u_b.data(), v_b.data());
    ASSERT_EQ(a, b) << trial;
    if (!a) {
      ++unseen;
      continue;
    }
    ++seen;
    // Eight corners and the centre; an unseen centre is NaN on both paths.
    for (std::size_t c = 0; c < 9; ++c) {
      if (c == 8 && std::isnan(u_a[c]) && std::isnan(u_b[c])) continue;
      ASSERT_EQ(std::memcmp(&u_a[c], &u_b[c], sizeof(float)), 0) << trial << " " << c;
      ASSERT_EQ(std::memcmp(&v_a[c], &v_b[c], sizeof(float)), 0) << trial << " " << c;
    }
  }
  EXPECT_GT(seen, 100);  // both outcomes are exercised
  EXPECT_GT(unseen, 20);
}

TEST(TsdfKernel, Avx2FootprintMaximumMatchesScalar) {
  if (!CpuHasAvx2()) GTEST_SKIP() << "no AVX2 on this CPU";
  constexpr int kWidth = 37, kHeight = 21;  // rows not a multiple of the eight lanes
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::vector<float> range(kWidth * kHeight);
  for (float& r : range) r = unit(rng) < 0.2f ? 0.0f : 1000.0f * unit(rng);
  std::uniform_int_distribution<int> column(0, kWidth - 1), row(0, kHeight - 1);
  for (int trial = 0; trial < 500; ++trial) {
    int u_lo = column(rng), u_hi = column(rng), v_lo = row(rng), v_hi = row(rng);
    if (u_lo > u_hi) std::swap(u_lo, u_hi);
    if (v_lo > v_hi) std::swap(v_lo, v_hi);
    float expected = 0.0f;  // the maximum, by definition
    for (int v = v_lo; v <= v_hi; ++v) {
      for (int u = u_lo; u <= u_hi; ++u) expected = std::max(expected, range[v * kWidth + u]);
    }
    ASSERT_EQ(MaxRangeInBox(range.data(), kWidth, u_lo, u_hi, v_lo, v_hi), expected) << trial;
    ASSERT_EQ(MaxRangeInBoxAvx2(range.data(), kWidth, u_lo, u_hi, v_lo, v_hi), expected) << trial;
  }
}

}  // namespace
}  // namespace tofnav
