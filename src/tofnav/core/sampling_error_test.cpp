// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/core/sampling_error.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "tofnav/core/require.hpp"
#include "tofnav/core/statistics.hpp"

namespace tofnav {
namespace {

// Tippett's tabulated d2 constants (four decimals): the integration is good to far better.
TEST(ExpectedRangeOfNormals, MatchesTippettsConstants) {
  constexpr double kTableTol = 5e-5;                                    // the table's rounding
  EXPECT_NEAR(ExpectedRangeOfNormals(2), 2.0 / std::sqrt(M_PI), 1e-9);  // closed form
  EXPECT_NEAR(ExpectedRangeOfNormals(3), 1.6926, kTableTol);
  EXPECT_NEAR(ExpectedRangeOfNormals(5), 2.3259, kTableTol);
  EXPECT_NEAR(ExpectedRangeOfNormals(10), 3.0775, kTableTol);
  EXPECT_THROW(ExpectedRangeOfNormals(1), PreconditionError);
}

// The standard error against the spread of the RMS over many independent runs of the same
// process: an AR(1) series (each value 0.7 of the last plus white noise, as a filter's output
// errs), 90 samples like a suite case's tracking. The estimate from one run, averaged over runs,
// must match the RMS's true spread within 20 %: overlapping batch means of sqrt(90) ~ 9 samples
// under-count an AR(1) of coefficient 0.7 slightly (its correlation lasts ~6 samples), and the
// delta method is first order.
TEST(RmsStandardError, MatchesTheSpreadOfTheRmsOverRunsOfACorrelatedSeries) {
  std::mt19937_64 rng(40);
  std::normal_distribution<double> noise(0.0, 0.1);
  constexpr int kRuns = 2000, kSamples = 90;
  std::vector<double> rms_of_run, se_of_run;
  for (int run = 0; run < kRuns; ++run) {
    std::vector<double> series(kSamples);
    double state = noise(rng) / std::sqrt(1.0 - 0.49);
    for (double& v : series) {
      state = 0.7 * state + noise(rng);
      v = 0.15 + state;  // a bias plus correlated noise, like a plate's error along the ray
    }
    rms_of_run.push_back(Rms(series));
    se_of_run.push_back(RmsStandardError(series));
  }
  const double true_spread = Summarise(rms_of_run).sd;
  const double estimated = Mean(se_of_run);
  EXPECT_NEAR(estimated / true_spread, 1.0, 0.2) << true_spread << " " << estimated;
  // White noise of the same variance has a smaller standard error: the estimate sees the
  // correlation (a plain sd / sqrt(n) would not).
  std::vector<double> white(kSamples);
  for (double& v : white) v = 0.15 + noise(rng) / std::sqrt(1.0 - 0.49);
  EXPECT_LT(RmsStandardError(white), 0.7 * estimated);
}

TEST(RmsStandardError, ZeroSeriesShortSeriesAndNan) {
  const std::vector<double> zeros(10, 0.0);
  EXPECT_EQ(RmsStandardError(zeros), 0.0);
  const std::vector<double> three{1.0, 2.0, 3.0};
  EXPECT_THROW(RmsStandardError(three), PreconditionError);
  const std::vector<double> nan{1.0, 2.0, NAN, 3.0, 4.0};
  EXPECT_THROW(RmsStandardError(nan), PreconditionError);
}

}  // namespace
}  // namespace tofnav
