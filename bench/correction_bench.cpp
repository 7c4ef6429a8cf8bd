// SPDX-License-Identifier: BSD-3-Clause
// Identification (Eq. 7, smoothness only) on 1000 frames of the size the CLI extracts.
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>

#include "correction_test_scenes.hpp"
#include "tofnav/correction/identification.hpp"

namespace tofnav {
namespace {

// 1000 sphere-head frames at 380-800 mm, 3 markers each with about 160 neighbours (the CLI's
// max_patch_points) and 17 marker points.
std::vector<IdentificationFrame> Frames() {
  DepthErrorModel truth;
  truth.c1_mm = 9.2, truth.c2 = 0.007, truth.c3_mm = 5.5;
  std::vector<IdentificationFrame> frames;
  for (int i = 0; i < 1000; ++i) {
    const double range = 380.0 + 420.0 * (i % 37) / 36.0;
    const Eigen::Vector3d centre =
        Eigen::AngleAxisd(0.02 * (i % 29) - 0.3, Eigen::Vector3d::UnitX()) *
        Eigen::Vector3d(2.0 * (i % 31) - 30.0, 0.0, range);
    frames.push_back(testing::SphereFrame(i, centre, truth, 40, 3.0));
  }
  return frames;
}

void BM_IdentifySmoothness1000Frames(benchmark::State& state) {
  const std::vector<IdentificationFrame> frames = Frames();
  for (auto _ : state) {
    benchmark::DoNotOptimize(IdentifyDepthModel(frames, nullptr, DepthErrorModel{}));
  }
}
BENCHMARK(BM_IdentifySmoothness1000Frames)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace
}  // namespace tofnav

BENCHMARK_MAIN();
