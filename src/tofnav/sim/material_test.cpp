// SPDX-License-Identifier: BSD-3-Clause
// Material presets and the f_rf(d) curves.
#include "tofnav/sim/material.hpp"

#include <gtest/gtest.h>

#include <stdexcept>

namespace tofnav::sim {
namespace {

constexpr double kCurveTolMm = 1e-6;  // closed-form curves: rounding only
constexpr double kEndTolMm = 0.05;    // the sigmoid only approaches 0 and 4 mm at the ends

TEST(RetroRangeBias, CurvesSpanZeroToAmplitudeOver300To700) {
  for (const RetroCurve curve :
       {RetroCurve::kLinear, RetroCurve::kQuadratic, RetroCurve::kSigmoid}) {
    EXPECT_NEAR(RetroRangeBiasMm(curve, 4.0, 300.0), 0.0, kEndTolMm);
    EXPECT_NEAR(RetroRangeBiasMm(curve, 4.0, 700.0), 4.0, kEndTolMm);
  }
  EXPECT_NEAR(RetroRangeBiasMm(RetroCurve::kLinear, 4.0, 500.0), 2.0, kCurveTolMm);
  EXPECT_NEAR(RetroRangeBiasMm(RetroCurve::kQuadratic, 4.0, 500.0), 1.0, kCurveTolMm);
  EXPECT_NEAR(RetroRangeBiasMm(RetroCurve::kSigmoid, 4.0, 500.0), 2.0, kCurveTolMm);
  EXPECT_NEAR(RetroRangeBiasMm(RetroCurve::kWavy, 4.0, 300.0), 1.5, kCurveTolMm);
  EXPECT_EQ(RetroRangeBiasMm(RetroCurve::kNone, 4.0, 500.0), 0.0);
  for (double d = 300.0; d <= 700.0; d += 10.0) {  // every shape stays in the paper's 0-4 mm band
    for (const RetroCurve curve :
         {RetroCurve::kLinear, RetroCurve::kQuadratic, RetroCurve::kSigmoid, RetroCurve::kWavy}) {
      EXPECT_GE(RetroRangeBiasMm(curve, 4.0, d), -kCurveTolMm);
      EXPECT_LE(RetroRangeBiasMm(curve, 4.0, d), 4.0 + kCurveTolMm);
    }
  }
}

TEST(RetroRangeBias, ExtendsLinearlyAndScalesWithAmplitude) {
  constexpr double kSlopeTolMm = 1e-4;  // one-sided difference of the end slope
  EXPECT_NEAR(RetroRangeBiasMm(RetroCurve::kLinear, 4.0, 800.0), 5.0, kSlopeTolMm);
  EXPECT_NEAR(RetroRangeBiasMm(RetroCurve::kLinear, 4.0, 200.0), -1.0, kSlopeTolMm);
  // Quadratic: value 4 and slope 8/400 at 700 mm; slope 0 at 300 mm.
  EXPECT_NEAR(RetroRangeBiasMm(RetroCurve::kQuadratic, 4.0, 750.0), 5.0, kSlopeTolMm);
  EXPECT_NEAR(RetroRangeBiasMm(RetroCurve::kQuadratic, 4.0, 100.0), 0.0, kSlopeTolMm);
  EXPECT_NEAR(RetroRangeBiasMm(RetroCurve::kWavy, 2.0, 456.0),
              0.5 * RetroRangeBiasMm(RetroCurve::kWavy, 4.0, 456.0), kCurveTolMm);
}

TEST(Material, PresetsAreValidAndDistinct) {
  for (const Material& m : {SkinMaterial(), NylonMaterial(), PhotopolymerMaterial(), PlaMaterial(),
                            PcAbsMaterial(), RetroReflectiveMaterial(), DiffuseMaterial(0.5)}) {
    EXPECT_NO_THROW(m.Check()) << m.name;
  }
  EXPECT_DOUBLE_EQ(SkinMaterial().albedo, 0.55);
  EXPECT_DOUBLE_EQ(PcAbsMaterial().albedo, 0.05);
  EXPECT_TRUE(RetroReflectiveMaterial().retro_reflective);
  EXPECT_FALSE(SkinMaterial().retro_reflective);
  EXPECT_EQ(RetroReflectiveMaterial(RetroCurve::kWavy).retro_curve, RetroCurve::kWavy);
  EXPECT_DOUBLE_EQ(SkinMaterial().model_c1_mm, 2.8);  // docs/tof_physics.md section 5.2
  EXPECT_DOUBLE_EQ(PhotopolymerMaterial().model_c3_mm_per_rad, 5.5);
}

TEST(Material, CheckRejectsBadFields) {
  Material m = DiffuseMaterial(0.5);
  m.albedo = 1.5;
  EXPECT_THROW(m.Check(), std::invalid_argument);
  m = SkinMaterial();
  m.subsurface_fraction = -0.1;
  EXPECT_THROW(m.Check(), std::invalid_argument);
  m = RetroReflectiveMaterial();
  m.retro_entrance_cutoff_rad = 2.0;
  EXPECT_THROW(m.Check(), std::invalid_argument);
}

}  // namespace
}  // namespace tofnav::sim
