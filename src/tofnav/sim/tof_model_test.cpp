// SPDX-License-Identifier: BSD-3-Clause
// Per-hit forward model: radiometry, subsurface delay, model-mode bias, noise law, wiggle.
#include "tofnav/sim/tof_model.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

namespace tofnav::sim {
namespace {

constexpr double kAbTableTol = 1.0;  // docs/tof_physics.md section 3 tabulates rounded counts

TEST(HitAmplitude, MatchesTheRadiometryTable) {
  const RadiometryOptions radiometry;
  const Material skin = SkinMaterial();
  EXPECT_NEAR(HitAmplitude(skin, radiometry, 180.0, 1.0, 1.0), 1103.0, kAbTableTol);
  EXPECT_NEAR(HitAmplitude(skin, radiometry, 300.0, 1.0, 1.0), 397.0, kAbTableTol);
  EXPECT_NEAR(HitAmplitude(skin, radiometry, 500.0, 1.0, 1.0), 143.0, kAbTableTol);
  EXPECT_NEAR(HitAmplitude(skin, radiometry, 700.0, 1.0, 1.0), 73.0, kAbTableTol);
  EXPECT_NEAR(HitAmplitude(DiffuseMaterial(0.5), radiometry, 500.0, 1.0, 1.0), 130.0, kAbTableTol);
}

TEST(HitAmplitude, FallsWithIncidenceAndOffAxisAngle) {
  const RadiometryOptions radiometry;
  const Material board = DiffuseMaterial(0.5);
  const double on_axis = HitAmplitude(board, radiometry, 500.0, 1.0, 1.0);
  EXPECT_DOUBLE_EQ(HitAmplitude(board, radiometry, 500.0, 0.5, 1.0), 0.5 * on_axis);
  EXPECT_DOUBLE_EQ(HitAmplitude(board, radiometry, 500.0, -0.5, 1.0), 0.5 * on_axis);  // back side
  EXPECT_NEAR(HitAmplitude(board, radiometry, 500.0, 1.0, std::cos(std::numbers::pi / 4.0)),
              0.5 * on_axis,
              1e-9);  // V = cos^2(45 deg)
}

TEST(HitAmplitude, RetroReflectorsOutshineSkinAndStopBeyondTheCutOff) {
  const RadiometryOptions radiometry;
  const Material retro = RetroReflectiveMaterial();
  for (const double d : {300.0, 500.0, 700.0}) {
    const double marker = HitAmplitude(retro, radiometry, d, 1.0, 1.0);
    EXPECT_GT(marker, 30.0 * HitAmplitude(SkinMaterial(), radiometry, d, 1.0, 1.0)) << d;
    EXPECT_GT(marker, 1280.0) << d;  // IRToolTrack threshold
  }
  const double beyond = std::cos(retro.retro_entrance_cutoff_rad + 0.01);
  EXPECT_DOUBLE_EQ(HitAmplitude(retro, radiometry, 500.0, beyond, 1.0),
                   HitAmplitude(DiffuseMaterial(retro.albedo), radiometry, 500.0, beyond, 1.0));
}

TEST(Subsurface, FiftyPicosecondsGiveSevenAndAHalfMillimetres) {
  constexpr double kBiasTolMm = 0.01;
  Material m = DiffuseMaterial(0.5);
  m.subsurface_fraction = 1.0;
  m.subsurface_delay_ps = 50.0;
  const SensorOptions sensor;
  EXPECT_NEAR(SubsurfaceBiasMm(m, 0.0, sensor), 7.49, kBiasTolMm);  // docs/tof_physics.md 5.1
  const std::complex<double> h = SubsurfaceFactor(m, 0.0, sensor.ModulationHz());
  EXPECT_GT(std::arg(h), 0.0);             // delayed light makes the surface appear farther
  EXPECT_NEAR(std::abs(h), 0.999, 0.001);  // negligible amplitude loss
  // Small w tau: bias ~ a c tau / 2.
  m.subsurface_fraction = 0.5;
  m.subsurface_delay_ps = 10.0;
  constexpr double kSpeedOfLightMmPerPs = 0.299792458;
  EXPECT_NEAR(SubsurfaceBiasMm(m, 0.0, sensor), 0.5 * kSpeedOfLightMmPerPs * 10.0 / 2.0,
              kBiasTolMm);
}

TEST(Subsurface, GrowsWithIncidenceForPositiveAngleGain) {
  const SensorOptions sensor;
  const Material skin = SkinMaterial();
  EXPECT_GT(SubsurfaceBiasMm(skin, 0.6, sensor), SubsurfaceBiasMm(skin, 0.0, sensor));
  const double skin_bias = SubsurfaceBiasMm(skin, 0.35, sensor);
  EXPECT_GT(skin_bias, 6.5);  // paper: 7.58 +- 1.49 mm on skin
  EXPECT_LT(skin_bias, 8.5);
}

TEST(AdditiveBias, ModelModeIsThePapersLinearModel) {
  const SensorOptions sensor;
  const Material nylon = NylonMaterial();
  EXPECT_DOUBLE_EQ(AdditiveBiasMm(nylon, BiasMode::kModel, 400.0, 0.3, 100.0, sensor),
                   nylon.model_c1_mm + nylon.model_c2 * 400.0 + nylon.model_c3_mm_per_rad * 0.3);
  EXPECT_EQ(AdditiveBiasMm(nylon, BiasMode::kNone, 400.0, 0.3, 100.0, sensor), 0.0);
  EXPECT_EQ(AdditiveBiasMm(RetroReflectiveMaterial(), BiasMode::kNone, 600.0, 0.3, 1e4, sensor),
            0.0);
}

TEST(AdditiveBias, PhysicalModeHasTheIntensityTermAndRetroCurve) {
  const SensorOptions sensor;
  const Material nylon = NylonMaterial();
  EXPECT_DOUBLE_EQ(AdditiveBiasMm(nylon, BiasMode::kPhysical, 400.0, 0.3, 50.0, sensor),
                   nylon.intensity_bias_gain_mm * std::log(sensor.intensity_reference_ab / 50.0));
  const Material retro = RetroReflectiveMaterial(RetroCurve::kLinear);
  for (const BiasMode mode : {BiasMode::kPhysical, BiasMode::kModel}) {
    // f_rf's linear curve at 500 mm (half of 4 mm) plus the entrance-angle term at 0.1 rad.
    EXPECT_DOUBLE_EQ(AdditiveBiasMm(retro, mode, 500.0, 0.1, 4e4, sensor),
                     2.0 + 0.1 * retro.retro_angle_gain_mm_per_rad);
    EXPECT_DOUBLE_EQ(AdditiveBiasMm(retro, mode, 500.0, 0.0, 4e4, sensor), 2.0);
  }
  Material tilted = retro;  // the entrance-angle term (docs/simulator.md 10)
  tilted.retro_angle_gain_mm_per_rad = 2.1;
  EXPECT_DOUBLE_EQ(AdditiveBiasMm(tilted, BiasMode::kPhysical, 500.0, 0.5, 4e4, sensor),
                   2.0 + 2.1 * 0.5);
}

TEST(DepthNoise, FollowsTheShotNoiseLawAboveTheFloor) {
  const NoiseOptions noise;
  EXPECT_DOUBLE_EQ(DepthNoiseSigmaMm(noise, 130.0, 350.0), 1.0);
  EXPECT_DOUBLE_EQ(DepthNoiseSigmaMm(noise, 520.0, 350.0), 0.5);
  EXPECT_DOUBLE_EQ(DepthNoiseSigmaMm(noise, 40000.0, 350.0), 0.3);
  EXPECT_EQ(DepthNoiseSigmaMm(noise, 0.0, 350.0), std::numeric_limits<double>::infinity());
}

// With exponent 1.5 a bright pixel's floor grows as range^1.5: 0.3 mm at 350 mm, 0.85 mm at
// 700 mm, the rise STTAR measured on one marker pixel (docs/simulator.md 10.1).
TEST(DepthNoise, TheFloorGrowsWithRange) {
  NoiseOptions noise;  // the default since session 29: 1.5
  EXPECT_DOUBLE_EQ(DepthNoiseSigmaMm(noise, 40000.0, 700.0), 0.3 * std::pow(2.0, 1.5));
  EXPECT_DOUBLE_EQ(DepthNoiseSigmaMm(noise, 130.0, 700.0), 1.0);    // shot noise above it
  EXPECT_DOUBLE_EQ(DepthNoiseSigmaMm(noise, 40000.0, 350.0), 0.3);  // the reference range
  noise.depth_sigma_floor_exponent = 0.0;                           // flat, as before
  EXPECT_DOUBLE_EQ(DepthNoiseSigmaMm(noise, 40000.0, 700.0), 0.3);
}

TEST(Wiggle, IsASinusoidOfPeriodLOverThree) {
  SensorOptions sensor;
  EXPECT_NEAR(sensor.ModulationHz(), 142.08e6, 0.01e6);
  // The default phase (3.5 rad, docs/simulator.md 10): lowest at 419.5 mm, highest at 595.4 mm.
  const double period_mm = 1055.0 / 3.0;
  const double low_mm = (3.5 * std::numbers::pi - 3.5) * period_mm / (2.0 * std::numbers::pi);
  EXPECT_NEAR(low_mm, 419.5, 0.1);
  EXPECT_NEAR(WiggleMm(sensor, low_mm), -1.0, 1e-12);
  EXPECT_NEAR(WiggleMm(sensor, low_mm + period_mm / 2.0), 1.0, 1e-12);
  sensor.wiggle_phase_rad = 0.0;
  EXPECT_NEAR(WiggleMm(sensor, 1055.0 / 12.0), 1.0, 1e-12);
  EXPECT_NEAR(WiggleMm(sensor, 100.0), WiggleMm(sensor, 100.0 + 1055.0 / 3.0), 1e-12);
  sensor.wiggle_amplitude_mm = 0.0;
  EXPECT_EQ(WiggleMm(sensor, 88.0), 0.0);
}

}  // namespace
}  // namespace tofnav::sim
