// SPDX-License-Identifier: BSD-3-Clause
// Stage range errors from synthetic disc detections with a known f_rf (the rendered case is in
// tests/tracking_e2e_test.cpp).
#include "tofnav/tracking/linear_stage.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>

#include "tofnav/sim/material.hpp"
#include "tracking_test_tools.hpp"

namespace tofnav {
namespace {

// Sixty frames (0.2 s apart) of the structure at `position(t)`, turned by (tilt_x, tilt_y) rad:
// marker rays with Gaussian noise, ranges = true + `bias(true)` + Gaussian noise.
template <typename Position, typename Bias>
std::vector<StageFrame> SyntheticStage(const ToolGeometry& structure, Position position,
                                       double tilt_x, double tilt_y, Bias bias,
                                       double ray_noise_rad, double range_noise_mm,
                                       std::mt19937_64& rng) {
  std::normal_distribution<double> range_noise, ray_noise;  // standard: scaled below (sigma 0 ok)
  std::vector<StageFrame> frames;
  for (int f = 0; f < 60; ++f) {
    const double t = 0.2 * f;
    const Rigid3d pose = testing::FacingToolPose(position(t), tilt_x, tilt_y);
    StageFrame frame{t, {}};
    for (const Eigen::Vector3d& m : structure.markers_in_tool) {
      const Eigen::Vector3d c = pose * m;
      DetectedMarker d;
      d.ray_in_ahat =
          (c.normalized() + ray_noise_rad * Eigen::Vector3d(ray_noise(rng), ray_noise(rng), 0.0))
              .normalized();
      d.surface_range_mm = c.norm() + bias(c.norm()) + range_noise_mm * range_noise(rng);
      frame.markers.push_back(d);
    }
    frames.push_back(frame);
  }
  return frames;
}

TEST(MeasureMarkerRangeErrors, RecoversTheRangeErrorCurveFromRaysAndBiasedRanges) {
  constexpr double kRangeNoiseMm = 0.4, kRayNoiseRad = 2e-4;  // ~0.05 px of centroid noise
  constexpr double kMeanErrorTolMm = 0.12;  // per 100 mm bin: 3 sigma of ~100 samples
  std::mt19937_64 rng(1);
  const ToolGeometry structure = testing::StageStructure(0.0);
  // The stage moves 7 mm per frame away from the camera.
  const std::vector<StageFrame> frames = SyntheticStage(
      structure, [](double t) { return Eigen::Vector3d(8.0, -6.0, 290.0 + 35.0 * t); }, 0.05, 0.1,
      [](double d) { return sim::RetroRangeBiasMm(sim::RetroCurve::kSigmoid, 4.0, d); },
      kRayNoiseRad, kRangeNoiseMm, rng);
  const StageRangeErrorResult r = MeasureMarkerRangeErrors(frames, structure);
  EXPECT_EQ(r.frames_used, 60);
  ASSERT_EQ(r.samples.size(), 60u * 7u);
  EXPECT_NEAR(r.line_velocity_mm_per_s.z(), 35.0, 0.05);  // the stage moves along ahat z
  // Mean error per 100 mm bin against the curve at each sample's reference (true) range.
  for (double lo = 300.0; lo < 700.0; lo += 100.0) {
    double sum = 0.0;
    int n = 0;
    for (const MarkerRangeSample& s : r.samples) {
      if (s.range_mm < lo || s.range_mm >= lo + 100.0) continue;
      const double reference_mm = s.range_mm - s.error_mm;
      sum += s.error_mm - sim::RetroRangeBiasMm(sim::RetroCurve::kSigmoid, 4.0, reference_mm);
      ++n;
    }
    ASSERT_GT(n, 50) << lo;
    EXPECT_NEAR(sum / n, 0.0, kMeanErrorTolMm) << lo;
  }
  EXPECT_THROW(MeasureMarkerRangeErrors(std::span(frames).first(3), structure),
               std::invalid_argument);
}

TEST(MeasureMarkerRangeErrors, AKnownStageSpeedLeavesOnlyTheOriginToFit) {
  constexpr double kSpeedMmPerS = 35.0;
  constexpr double kRayNoiseRad = 5e-4;   // ~0.12 px of centroid noise: PnP depth noise of mm
  constexpr double kEndErrorTolMm = 0.3;  // the origin from 60 PnP positions of mm-level noise
  std::mt19937_64 rng(3);
  const ToolGeometry structure = testing::StageStructure(0.0);
  const auto truth = [&](double t) { return Eigen::Vector3d(8.0, -6.0, 290.0 + kSpeedMmPerS * t); };
  const std::vector<StageFrame> frames = SyntheticStage(
      structure, truth, 0.0, 0.0, [](double) { return 0.0; }, kRayNoiseRad, 0.0, rng);
  StageRangeErrorOptions options;
  options.max_line_residual_mm = 50.0;  // keep every frame of this noisy run
  const StageRangeErrorResult free = MeasureMarkerRangeErrors(frames, structure, options);
  options.known_speed_mm_per_s = kSpeedMmPerS;
  const StageRangeErrorResult known = MeasureMarkerRangeErrors(frames, structure, options);
  EXPECT_NEAR(known.line_velocity_mm_per_s.norm(), kSpeedMmPerS, 1e-9);
  EXPECT_NEAR(known.fitted_speed_mm_per_s, free.line_velocity_mm_per_s.norm(), 1e-9);
  const auto end_error = [&](const StageRangeErrorResult& r) {
    double worst = 0.0;
    for (const double t : {0.0, 11.8}) {
      worst = std::max(worst, (r.line_origin_mm + r.line_velocity_mm_per_s * t - truth(t)).norm());
    }
    return worst;
  };
  std::printf("line error at the ends: free %.3f mm, known speed %.3f mm\n", end_error(free),
              end_error(known));
  EXPECT_LT(end_error(known), kEndErrorTolMm);
  EXPECT_LT(end_error(known), end_error(free));
}

// The reference line's mean error along the ray over a run, from `runs` seeds of a structure
// turned by `tilt_rad` moving 300 -> 690 mm at a known speed, with ~0.25 px of centroid noise
// (a far 10 mm disc).
double MeanAlongRayErrorMm(double tilt_rad, int runs) {
  constexpr double kSpeedMmPerS = 32.5;
  const ToolGeometry structure = testing::StageStructure(0.0);
  const auto truth = [&](double t) { return Eigen::Vector3d(8.0, -6.0, 300.0 + kSpeedMmPerS * t); };
  StageRangeErrorOptions options;
  options.max_line_residual_mm = 50.0;
  options.known_speed_mm_per_s = kSpeedMmPerS;
  double sum = 0.0;
  int n = 0;
  for (int seed = 0; seed < runs; ++seed) {
    std::mt19937_64 rng(100 + static_cast<std::uint64_t>(seed));
    const std::vector<StageFrame> frames = SyntheticStage(
        structure, truth, tilt_rad, 0.0, [](double) { return 0.0; }, 1e-3, 0.0, rng);
    const StageRangeErrorResult r = MeasureMarkerRangeErrors(frames, structure, options);
    for (const StageFrame& f : frames) {
      const Eigen::Vector3d error =
          r.line_origin_mm + r.line_velocity_mm_per_s * f.timestamp_s - truth(f.timestamp_s);
      sum += error.dot(truth(f.timestamp_s).normalized());
      ++n;
    }
  }
  return sum / n;
}

// Posed frame by frame, a frontal structure lies too near (PnP fits its foreshortened size, and
// a tilt error e shortens the range by d e^2 / 2; near a frontal view e is degrees) and a tilted
// one does not: the runs' difference then entered f_rf's entrance gain (docs/tracking.md 4). One
// rotation and one line fitted to all rays of the run leave neither.
TEST(MeasureMarkerRangeErrors, TheReferenceLiesOnTheStageAtFrontalAndTiltedViews) {
  constexpr double kTolMm = 0.08;  // 20 runs: the line's offset scatters ~0.2 mm per run
  const double frontal = MeanAlongRayErrorMm(0.0, 20);
  const double tilted = MeanAlongRayErrorMm(0.5, 20);
  std::printf("reference along the ray: frontal %+.3f mm, 29 deg %+.3f mm\n", frontal, tilted);
  EXPECT_NEAR(frontal, 0.0, kTolMm);
  EXPECT_NEAR(tilted, 0.0, kTolMm);
}

}  // namespace
}  // namespace tofnav
