// SPDX-License-Identifier: BSD-3-Clause
// AHAT camera: construction, Project over a frame's worth of points, PointFromRange per frame.
#include <benchmark/benchmark.h>

#include <vector>

#include "tofnav/core/point_cloud.hpp"
#include "tofnav/sensor/ahat_camera.hpp"
#include "tofnav/sensor/ahat_frame.hpp"

namespace tofnav {
namespace {

constexpr double kRangeMm = 500.0;

const AhatCalibration& Calibration() {
  static const AhatCalibration calibration = MakeSyntheticAhatCalibration();
  return calibration;
}

void BM_MakeSyntheticAhatCalibration(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(MakeSyntheticAhatCalibration());
}
BENCHMARK(BM_MakeSyntheticAhatCalibration)->Unit(benchmark::kMillisecond);

void BM_AhatCameraConstruct(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(AhatCamera(Calibration()));
}
BENCHMARK(BM_AhatCameraConstruct)->Unit(benchmark::kMillisecond);

/// One point per valid pixel, off the pixel centres, projected back: a frame's worth.
void BM_ProjectFrame(benchmark::State& state) {
  const AhatCamera camera(Calibration());
  Points3d points;
  for (int v = 0; v < camera.height(); ++v) {
    for (int u = 0; u < camera.width(); ++u) {
      if (const auto ray = camera.Ray(Eigen::Vector2d(u + 0.37, v + 0.61))) {
        points.push_back((kRangeMm + u) * *ray);
      }
    }
  }
  for (auto _ : state) {
    for (const Eigen::Vector3d& point : points) benchmark::DoNotOptimize(camera.Project(point));
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(points.size()));
}
BENCHMARK(BM_ProjectFrame)->Unit(benchmark::kMillisecond);

/// Back-projects a full 512 x 512 range frame into a point cloud (valid pixels only).
void BM_PointFromRangeFrame(benchmark::State& state) {
  const AhatCamera camera(Calibration());
  Image<std::uint16_t> range_mm(kAhatWidth, kAhatHeight);
  for (int v = 0; v < kAhatHeight; ++v) {
    for (int u = 0; u < kAhatWidth; ++u) range_mm(u, v) = static_cast<std::uint16_t>(400 + u);
  }
  Points3d points;
  points.reserve(kAhatPixels);
  for (auto _ : state) {
    points.clear();
    for (int v = 0; v < kAhatHeight; ++v) {
      for (int u = 0; u < kAhatWidth; ++u) {
        if (range_mm(u, v) == 0 || !camera.IsValid(u, v)) continue;
        points.push_back(camera.PointFromRange(u, v, range_mm(u, v)));
      }
    }
    benchmark::DoNotOptimize(points.data());
  }
  state.SetItemsProcessed(state.iterations() * kAhatPixels);
}
BENCHMARK(BM_PointFromRangeFrame)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace tofnav

BENCHMARK_MAIN();
