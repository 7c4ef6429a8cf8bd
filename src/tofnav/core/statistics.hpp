// SPDX-License-Identifier: BSD-3-Clause
// Sample statistics for every evaluation figure: one quantile definition, one summary.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

namespace tofnav {

/// The one quantile definition of tofnav (docs/statistics.md): linear interpolation between the
/// order statistics, Hyndman and Fan's type 7 (numpy's and R's default). For the n values sorted
/// ascending, x[0] <= ... <= x[n - 1], and q in [0, 1]:
///   h = q (n - 1),  Q(q) = x[floor h] + (h - floor h) (x[floor h + 1] - x[floor h]),
/// so Q(0) is the minimum, Q(1) the maximum and Q(0.5) the median (the mean of the two middle
/// values when n is even). Example: {1, 2, 3, 4} has median 2.5, p25 1.75, p75 3.25.
/// Every function below throws PreconditionError on an empty sample, a NaN value or q outside
/// [0, 1]; one value is its own every quantile.
double QuantileOfSorted(std::span<const double> sorted, double q);  // `sorted` ascending
double Quantile(std::span<const double> values, double q);          // any order
double Quantile(std::span<const float> values, double q);
double Median(std::span<const double> values);
double Iqr(std::span<const double> values);  // Q(0.75) - Q(0.25)
double P95(std::span<const double> values);  // Q(0.95)
double Mean(std::span<const double> values);
double Rms(std::span<const double> values);  // sqrt(mean of squares)
double Max(std::span<const double> values);

/// The same quantile of a sample of integers given as a histogram: counts[v] values equal v
/// (v = 0, 1, ...). Throws PreconditionError when every count is 0 or q is outside [0, 1].
double QuantileOfCounts(std::span<const std::uint64_t> counts, double q);

/// Figures of one sample. No unit in the field names: the member holding a Summary carries the
/// unit (`entry_mm`, `direction_deg`).
struct Summary {
  std::size_t count = 0;
  double mean = 0.0;
  double sd = 0.0;  // sample standard deviation (n - 1 in the denominator; 0 for one value)
  double rms = 0.0;
  double median = 0.0, p25 = 0.0, p75 = 0.0, p95 = 0.0;  // Quantile 0.5, 0.25, 0.75, 0.95
  double max = 0.0;
  double iqr() const { return p75 - p25; }
};

/// The Summary of a sample; an empty sample gives count 0 and every figure 0 (check count before
/// reading the figures). Throws PreconditionError on a NaN value.
Summary Summarise(std::span<const double> values);
Summary Summarise(std::span<const float> values);

}  // namespace tofnav
