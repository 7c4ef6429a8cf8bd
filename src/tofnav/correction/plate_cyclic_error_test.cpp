// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/correction/plate_cyclic_error.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace tofnav {
namespace {

constexpr double kPeriodMm = 1055.0 / 3.0;

// Four stage runs over 300-700 mm of a plate whose own bias is 19 mm + 2.5 ln(130 / AB) +
// 3 mm/rad theta + a run offset, seen by a sensor with a cyclic error of `amplitude` at `phase`;
// Gaussian noise of 1 mm and 2 % of the pixels 15-40 mm off (the tape's bloom, mixed pixels).
std::vector<PlateRangeSample> StageSamples(double amplitude_mm, double phase_rad,
                                           std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const CyclicRangeError truth{amplitude_mm, kPeriodMm, phase_rad};
  std::vector<PlateRangeSample> samples;
  for (int run = 0; run < 4; ++run) {
    for (double d = 300.0; d <= 700.0; d += 2.0) {
      for (int pixel = 0; pixel < 12; ++pixel) {
        const double theta = (10.0 * run + 2.0 * pixel - 11.0) * std::numbers::pi / 180.0;
        const double ab = 4000.0 * std::cos(std::abs(theta)) * (300.0 / d) * (300.0 / d);
        const double bias = 19.0 + 0.3 * run + 2.5 * std::log(130.0 / ab) + 3.0 * std::abs(theta);
        double measured = d + bias;
        measured += truth.Mm(measured) + noise(rng);
        if (unit(rng) < 0.02) measured += 15.0 + 25.0 * unit(rng);
        samples.push_back({measured, d, std::abs(theta), ab, run});
      }
    }
  }
  return samples;
}

// The fit's statistical error here is about 0.01 mm and 0.01 rad (9600 samples, 1 mm noise):
// the tolerances are five of those and hold only if the plate's own terms and the outliers are
// taken out rather than aliased into the sinusoid.
constexpr double kAmplitudeTolMm = 0.05;
constexpr double kPhaseTolRad = 0.05;

TEST(FitPlateCyclicError, RecoversTheSensorsWiggleBesideThePlatesOwnBias) {
  for (const auto& [amplitude, phase] : {std::pair{1.0, 3.5}, std::pair{0.6, -1.0}}) {
    const PlateCyclicFit fit = FitPlateCyclicError(StageSamples(amplitude, phase, 7), kPeriodMm);
    EXPECT_NEAR(fit.cyclic.amplitude_mm, amplitude, kAmplitudeTolMm);
    EXPECT_NEAR(std::remainder(fit.cyclic.phase_rad - phase, 2.0 * std::numbers::pi), 0.0,
                kPhaseTolRad);
    EXPECT_EQ(fit.cyclic.period_mm, kPeriodMm);
    EXPECT_NEAR(fit.intensity_mm, 2.5, 0.1);
    EXPECT_NEAR(fit.incidence_mm_per_rad, 3.0, 0.5);
    ASSERT_EQ(fit.run_offsets_mm.size(), 4u);
    EXPECT_NEAR(fit.run_offsets_mm[3] - fit.run_offsets_mm[0], 0.9, 0.1);
    EXPECT_GT(fit.amplitude_sd_mm, 0.0);
    EXPECT_LT(fit.amplitude_sd_mm, 0.03);
    EXPECT_NEAR(fit.span_mm, 400.0, 1e-9);
  }
}

TEST(FitPlateCyclicError, NoWiggleGivesNearZeroAmplitude) {
  const PlateCyclicFit fit = FitPlateCyclicError(StageSamples(0.0, 0.0, 11), kPeriodMm);
  EXPECT_LT(fit.cyclic.amplitude_mm, kAmplitudeTolMm);
}

TEST(FitPlateCyclicError, RefusesARangeSpanItCannotTell) {
  std::vector<PlateRangeSample> samples = StageSamples(1.0, 3.5, 3);
  std::erase_if(samples, [](const PlateRangeSample& s) { return s.plane_range_mm > 450.0; });
  try {
    FitPlateCyclicError(samples, kPeriodMm);
    FAIL() << "a 150 mm span was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("the plate's ranges span 150.0 mm, under 263.8 mm"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(FitPlateCyclicError({}, kPeriodMm), std::invalid_argument);
  EXPECT_THROW(FitPlateCyclicError(StageSamples(1.0, 3.5, 3), 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace tofnav
