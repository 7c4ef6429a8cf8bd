// SPDX-License-Identifier: BSD-3-Clause
// Zdepth decode/encode speed on a realistic 512x512 AHAT head frame (budget: decode <= 2 ms).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "tofnav/recording/zdepth.hpp"

namespace tofnav {
namespace {

/// AHAT-like range [mm]: a head dome (330..600 mm) in front of a tilted wall (~900 mm, aliasing
/// kept under 1055 mm), 1.5 mm noise, 1 % drop-outs, dark outside the 256 px illumination circle.
Image<std::uint16_t> HeadFrame() {
  constexpr int kSidePx = 512;
  constexpr double kCentreUPx = 252.4, kCentreVPx = 252.8, kIlluminationRadiusPx = 256.0;
  std::mt19937 rng(42);
  std::normal_distribution<double> noise_mm(0.0, 1.5);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Image<std::uint16_t> range_mm(kSidePx, kSidePx);
  for (int v = 0; v < kSidePx; ++v) {
    for (int u = 0; u < kSidePx; ++u) {
      const double du = u - kCentreUPx, dv = v - kCentreVPx;
      if (std::hypot(du, dv) > kIlluminationRadiusPx || unit(rng) < 0.01) continue;
      const double r2 = (std::pow(du + 20.0, 2) + std::pow(dv * 0.8, 2)) / (150.0 * 150.0);
      double d = 900.0 + 0.3 * du - 0.2 * dv;
      if (r2 < 1.0) d = 600.0 - 270.0 * std::sqrt(1.0 - r2);
      range_mm(u, v) = static_cast<std::uint16_t>(std::clamp(d + noise_mm(rng), 0.0, 1055.0));
    }
  }
  return range_mm;
}

void BM_DecodeZdepth(benchmark::State& state) {
  const std::vector<std::uint8_t> bytes = EncodeZdepth(HeadFrame());
  for (auto _ : state) benchmark::DoNotOptimize(DecodeZdepth(bytes));
  state.counters["frame_bytes"] = static_cast<double>(bytes.size());
}
BENCHMARK(BM_DecodeZdepth)->Unit(benchmark::kMillisecond);

void BM_EncodeZdepth(benchmark::State& state) {
  const Image<std::uint16_t> range_mm = HeadFrame();
  ZdepthEncodeOptions options;
  options.choose_predictors = state.range(0) != 0;
  for (auto _ : state) benchmark::DoNotOptimize(EncodeZdepth(range_mm, options));
}
BENCHMARK(BM_EncodeZdepth)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace tofnav

BENCHMARK_MAIN();
