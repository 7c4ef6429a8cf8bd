// SPDX-License-Identifier: BSD-3-Clause
// Eq. (1) fit on the simulator's f_rf curves and Eq. (2) on ranges, points and detections.
#include "tofnav/correction/marker_range_model.hpp"

#include <gtest/gtest.h>

#include <numbers>
#include <random>

#include "tofnav/markers/marker_centre.hpp"
#include "tofnav/sim/material.hpp"

namespace tofnav {
namespace {

constexpr double kNoiseMm = 0.4;      // per-marker range noise of a stage recording
constexpr double kCurveTolMm = 0.15;  // max |fit - truth| over 300-700 mm, 2000 noisy samples

TEST(FitMarkerRangeModel, RecoversEverySimulatorCurveWithinATenthOfAMillimetre) {
  for (const sim::RetroCurve curve : {sim::RetroCurve::kLinear, sim::RetroCurve::kQuadratic,
                                      sim::RetroCurve::kSigmoid, sim::RetroCurve::kWavy}) {
    std::mt19937_64 rng(static_cast<std::uint64_t>(curve));
    std::normal_distribution<double> noise(0.0, kNoiseMm);
    std::uniform_real_distribution<double> range(280.0, 720.0);
    std::vector<MarkerRangeSample> samples;
    for (int i = 0; i < 2000; ++i) {
      const double d_true = range(rng);
      const double d = std::round(d_true + sim::RetroRangeBiasMm(curve, 4.0, d_true) + noise(rng));
      samples.push_back({d, d - d_true, 1.0});
    }
    const MarkerRangeFitResult r = FitMarkerRangeModel(samples);
    double worst = 0.0;
    for (double d_true = 300.0; d_true <= 700.0; d_true += 2.0) {
      const double d = d_true + sim::RetroRangeBiasMm(curve, 4.0, d_true);
      worst = std::max(worst, std::abs(CorrectMarkerRange(d, r.model) - d_true));
    }
    EXPECT_LT(worst, kCurveTolMm) << static_cast<int>(curve);
    EXPECT_NEAR(r.rms_residual_mm, std::sqrt(kNoiseMm * kNoiseMm + 1.0 / 12.0), 0.05);
  }
}

// A stage's four runs at 0, 10, 20 and 30 deg: the tape reads farther by 2.1 mm/rad of entrance
// angle on top of the linear 4 mm curve (the simulator's retro sheeting, docs/simulator.md 10).
TEST(FitMarkerRangeModel, SeparatesTheEntranceAngleGainFromTheRangeCurve) {
  constexpr double kGainMmPerRad = 2.1;
  constexpr double kGainTolMmPerRad = 0.1;  // 2000 samples of 0.4 mm noise over 0-0.52 rad
  std::mt19937_64 rng(11);
  std::normal_distribution<double> noise(0.0, kNoiseMm);
  std::uniform_real_distribution<double> range(280.0, 720.0);
  std::vector<MarkerRangeSample> samples;
  for (int i = 0; i < 2000; ++i) {
    const double beta = (i % 4) * 10.0 * std::numbers::pi / 180.0;
    const double d_true = range(rng);
    const double d =
        std::round(d_true + sim::RetroRangeBiasMm(sim::RetroCurve::kLinear, 4.0, d_true) +
                   kGainMmPerRad * beta + noise(rng));
    samples.push_back({d, d - d_true, 1.0, beta});
  }
  const MarkerRangeFitResult r = FitMarkerRangeModel(samples);
  EXPECT_NEAR(r.model.entrance_gain_mm_per_rad, kGainMmPerRad, kGainTolMmPerRad);
  double worst = 0.0;  // f_rf(d, beta) against the truth at every range and tilt
  for (double d_true = 300.0; d_true <= 700.0; d_true += 5.0) {
    for (int k = 0; k < 4; ++k) {
      const double beta = k * 10.0 * std::numbers::pi / 180.0;
      const double d = d_true + sim::RetroRangeBiasMm(sim::RetroCurve::kLinear, 4.0, d_true) +
                       kGainMmPerRad * beta;
      worst = std::max(worst, std::abs(d - r.model.BiasMm(d, beta) - d_true));
    }
  }
  EXPECT_LT(worst, kCurveTolMm);
  // Range only (the paper's Eq. 1): no gain, and the same samples leave the angle's spread.
  const MarkerRangeFitResult paper = FitMarkerRangeModel(samples, {}, false);
  EXPECT_EQ(paper.model.entrance_gain_mm_per_rad, 0.0);
  EXPECT_GT(paper.rms_residual_mm, r.rms_residual_mm + 0.1);
  // Samples at one angle (spheres, one tilt) do not fit a gain.
  for (MarkerRangeSample& sample : samples) sample.entrance_rad = 0.3;
  EXPECT_EQ(FitMarkerRangeModel(samples).model.entrance_gain_mm_per_rad, 0.0);
}

TEST(MarkerRangeModel, BeyondTheKnotsFollowsTheLastFiftyMillimetresNotTheLastInterval) {
  // A curve rising 0.025 mm/mm whose last interval (one noisy sample) turns down: its end tangent
  // says -0.05 mm/mm, which 30 mm beyond the last knot would be 1.5 mm off (a 740 mm marker of a
  // stage run that ended at 709 mm, docs/tracking.md 4).
  MarkerRangeModel model;
  model.bias_mm.x = {300.0, 400.0, 500.0, 600.0, 650.0, 700.0, 709.0};
  model.bias_mm.value = {-1.0, 1.5, 4.0, 6.5, 7.75, 9.0, 8.55};
  model.bias_mm.second_derivative.assign(7, 0.0);  // piecewise linear: the slopes read exactly
  constexpr double kExact = 1e-9;
  EXPECT_NEAR(model.BiasMm(709.0), 8.55, kExact);  // inside: the spline itself
  EXPECT_NEAR(model.BiasMm(500.0), 4.0, kExact);
  const double secant_above = (8.55 - model.bias_mm.Evaluate(659.0)) / 50.0;
  EXPECT_NEAR(model.BiasMm(739.0), 8.55 + 30.0 * secant_above, kExact);
  EXPECT_GT(secant_above, 0.0);  // where the curve was heading, unlike the last interval
  EXPECT_NEAR(model.BiasMm(280.0), -1.0 - 20.0 * 0.025, kExact);  // below: the first 50 mm
}

TEST(CorrectMarkerRange, AppliesEquationTwoToRangesPointsAndDetections) {
  MarkerRangeModel model;
  model.bias_mm = {{300.0, 700.0}, {0.0, 4.0}, {0.0, 0.0}};  // 0.01 mm per mm
  EXPECT_DOUBLE_EQ(CorrectMarkerRange(500.0, model), 498.0);
  EXPECT_DOUBLE_EQ(CorrectMarkerRange(800.0, model), 795.0);  // linear extension
  const Eigen::Vector3d m(120.0, -90.0, 480.0);
  const Eigen::Vector3d corrected = CorrectMarkerPoint(m, model);
  EXPECT_NEAR(corrected.norm(), m.norm() - model.BiasMm(m.norm()), 1e-12);
  EXPECT_NEAR(corrected.normalized().dot(m.normalized()), 1.0, 1e-15);
  EXPECT_TRUE(CorrectMarkerPoint(Eigen::Vector3d::Zero(), model).isZero());
  EXPECT_DOUBLE_EQ(CorrectMarkerRange(432.0, MarkerRangeModel{}), 432.0);  // empty: identity

  DetectedMarker detected;
  detected.surface_range_mm = 600.0;
  detected.core = {{599.0f, 0.001f}, {600.0f, 0.0f}, {601.0f, 0.002f}};
  detected.pixel_pitch_rad = 1.0 / 254.0;
  const std::vector<DetectedMarker> out = CorrectMarkerRanges({detected}, model);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_DOUBLE_EQ(out[0].surface_range_mm, 597.0);
  EXPECT_FLOAT_EQ(out[0].core[0].range_mm, 596.0f);
  // The centre moves by the correction (the radius is added after it), up to the change of the
  // sphere footprint term with range (~2 t dt / t^2 of a 0.05 mm term).
  constexpr double kFootprintTolMm = 2e-3;
  EXPECT_NEAR(CentreRangeMm(out[0], 5.0, out[0].surface_range_mm),
              CentreRangeMm(detected, 5.0, detected.surface_range_mm) - 3.0, kFootprintTolMm);
}

}  // namespace
}  // namespace tofnav
