// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/core/statistics.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "tofnav/core/require.hpp"

namespace tofnav {
namespace {

// Hand-computed figures are exact in binary up to the last bit of the arithmetic.
constexpr double kExactTol = 1e-12;

TEST(Quantile, InterpolatesBetweenOrderStatistics) {
  const std::vector<double> v{4.0, 1.0, 3.0, 2.0};  // any order
  EXPECT_NEAR(Median(v), 2.5, kExactTol);
  EXPECT_NEAR(Quantile(v, 0.25), 1.75, kExactTol);  // h = 0.75: 1 + 0.75 (2 - 1)
  EXPECT_NEAR(Quantile(v, 0.75), 3.25, kExactTol);  // h = 2.25: 3 + 0.25 (4 - 3)
  EXPECT_NEAR(Quantile(v, 0.95), 3.85, kExactTol);  // h = 2.85: 3 + 0.85 (4 - 3)
  EXPECT_NEAR(Quantile(v, 0.0), 1.0, kExactTol);
  EXPECT_NEAR(Quantile(v, 1.0), 4.0, kExactTol);
  EXPECT_NEAR(Iqr(v), 1.5, kExactTol);
  EXPECT_NEAR(P95(v), 3.85, kExactTol);
}

TEST(Quantile, OddCountMedianIsTheMiddleValue) {
  const std::vector<double> v{5.0, -1.0, 3.0, 10.0, 0.0};
  EXPECT_NEAR(Median(v), 3.0, kExactTol);
  EXPECT_NEAR(Quantile(v, 0.25), 0.0, kExactTol);  // h = 1
  EXPECT_NEAR(Quantile(v, 0.1), -0.6, kExactTol);  // h = 0.4: -1 + 0.4 (0 - -1)
  const std::vector<float> f{5.0f, -1.0f, 3.0f, 10.0f, 0.0f};
  EXPECT_NEAR(Quantile(f, 0.5), 3.0, kExactTol);
}

TEST(Quantile, OneValueIsEveryQuantile) {
  const std::vector<double> v{7.5};
  for (const double q : {0.0, 0.25, 0.5, 0.95, 1.0}) EXPECT_EQ(Quantile(v, q), 7.5);
  EXPECT_EQ(Iqr(v), 0.0);
}

TEST(Quantile, RejectsEmptySamplesNanAndLevelsOutsideZeroOne) {
  const std::vector<double> empty, v{1.0, 2.0}, with_nan{1.0, NAN};
  EXPECT_THROW(Median(empty), PreconditionError);
  EXPECT_THROW(Mean(empty), PreconditionError);
  EXPECT_THROW(Rms(empty), PreconditionError);
  EXPECT_THROW(Max(empty), PreconditionError);
  EXPECT_THROW(Quantile(v, -0.1), PreconditionError);
  EXPECT_THROW(Quantile(v, 1.1), PreconditionError);
  EXPECT_THROW(Quantile(v, NAN), PreconditionError);
  EXPECT_THROW(Median(with_nan), PreconditionError);
}

TEST(QuantileOfCounts, MatchesTheSampleTheHistogramHolds) {
  const std::vector<std::uint64_t> counts{0, 2, 1, 1};  // the sample {1, 1, 2, 3}
  const std::vector<double> sample{1.0, 1.0, 2.0, 3.0};
  for (const double q : {0.0, 0.25, 0.5, 0.75, 0.99, 1.0}) {
    EXPECT_NEAR(QuantileOfCounts(counts, q), Quantile(sample, q), kExactTol) << q;
  }
  EXPECT_NEAR(QuantileOfCounts(counts, 0.5), 1.5, kExactTol);
  EXPECT_NEAR(QuantileOfCounts(counts, 0.75), 2.25, kExactTol);  // h = 2.25: 2 + 0.25 (3 - 2)
  EXPECT_EQ(QuantileOfCounts(std::vector<std::uint64_t>{0, 0, 5}, 0.3), 2.0);
  EXPECT_THROW(QuantileOfCounts(std::vector<std::uint64_t>{0, 0}, 0.5), PreconditionError);
}

TEST(Summarise, FiguresOfASample) {
  const std::vector<double> v{1.0, 2.0, 3.0, 4.0};
  const Summary s = Summarise(v);
  EXPECT_EQ(s.count, 4u);
  EXPECT_NEAR(s.mean, 2.5, kExactTol);
  EXPECT_NEAR(s.sd, std::sqrt(5.0 / 3.0), kExactTol);  // squared deviations 5 over n - 1 = 3
  EXPECT_NEAR(s.rms, std::sqrt(7.5), kExactTol);       // (1 + 4 + 9 + 16) / 4
  EXPECT_NEAR(s.median, 2.5, kExactTol);
  EXPECT_NEAR(s.p25, 1.75, kExactTol);
  EXPECT_NEAR(s.p75, 3.25, kExactTol);
  EXPECT_NEAR(s.p95, 3.85, kExactTol);
  EXPECT_NEAR(s.iqr(), 1.5, kExactTol);
  EXPECT_EQ(s.max, 4.0);
  EXPECT_NEAR(Mean(v), 2.5, kExactTol);
  EXPECT_NEAR(Rms(v), std::sqrt(7.5), kExactTol);
  EXPECT_EQ(Max(v), 4.0);
}

TEST(Summarise, EmptyAndOneValue) {
  const Summary empty = Summarise(std::vector<double>{});
  EXPECT_EQ(empty.count, 0u);
  EXPECT_EQ(empty.median, 0.0);
  EXPECT_EQ(empty.max, 0.0);
  const Summary one = Summarise(std::vector<float>{-2.0f});
  EXPECT_EQ(one.count, 1u);
  EXPECT_EQ(one.mean, -2.0);
  EXPECT_EQ(one.sd, 0.0);
  EXPECT_EQ(one.rms, 2.0);
  EXPECT_EQ(one.median, -2.0);
  EXPECT_EQ(one.p95, -2.0);
  EXPECT_EQ(one.max, -2.0);
  EXPECT_THROW(Summarise(std::vector<double>{NAN}), PreconditionError);
}

}  // namespace
}  // namespace tofnav
