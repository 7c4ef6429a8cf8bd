// SPDX-License-Identifier: BSD-3-Clause
// Type 7 quantiles (linear interpolation between order statistics) and sample summaries.
#include "tofnav/core/statistics.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "tofnav/core/require.hpp"

namespace tofnav {
namespace {

template <typename T>
std::vector<double> SortedCopy(std::span<const T> values) {
  std::vector<double> sorted(values.begin(), values.end());
  Require(std::none_of(sorted.begin(), sorted.end(), [](double v) { return std::isnan(v); }),
          "statistics of a sample with a NaN value");
  std::sort(sorted.begin(), sorted.end());
  return sorted;
}

void RequireSample(std::size_t n) { Require(n > 0, "statistics of an empty sample"); }

// Type 7: the position h = q (n - 1) among the n order statistics, split into its whole and
// fractional parts (n > 0, q checked).
struct Rank {
  std::size_t i = 0;  // x[i] and x[i + 1] (when there is one) bracket the quantile
  double fraction = 0.0;
};
Rank RankOf(std::size_t n, double q) {
  RequireSample(n);
  Require(q >= 0.0 && q <= 1.0, "quantile level outside [0, 1]");
  const double h = q * static_cast<double>(n - 1);
  const auto i = std::min(static_cast<std::size_t>(std::floor(h)), n - 1);
  return {i, h - static_cast<double>(i)};
}

double Interpolate(double lower, double upper, double fraction) {
  return fraction > 0.0 ? lower + fraction * (upper - lower) : lower;
}

Summary SummariseSorted(const std::vector<double>& sorted) {
  Summary s;
  s.count = sorted.size();
  if (sorted.empty()) return s;
  const auto n = static_cast<double>(s.count);
  double sum = 0.0, sum2 = 0.0;
  for (const double v : sorted) sum += v, sum2 += v * v;
  s.mean = sum / n;
  s.rms = std::sqrt(sum2 / n);
  double deviations2 = 0.0;  // two passes: no cancellation when the mean dwarfs the spread
  for (const double v : sorted) deviations2 += (v - s.mean) * (v - s.mean);
  s.sd = s.count > 1 ? std::sqrt(deviations2 / (n - 1.0)) : 0.0;
  s.median = QuantileOfSorted(sorted, 0.5);
  s.p25 = QuantileOfSorted(sorted, 0.25);
  s.p75 = QuantileOfSorted(sorted, 0.75);
  s.p95 = QuantileOfSorted(sorted, 0.95);
  s.max = sorted.back();
  return s;
}

}  // namespace

double QuantileOfSorted(std::span<const double> sorted, double q) {
  const Rank r = RankOf(sorted.size(), q);
  if (r.i + 1 >= sorted.size()) return sorted[r.i];
  return Interpolate(sorted[r.i], sorted[r.i + 1], r.fraction);
}

double QuantileOfCounts(std::span<const std::uint64_t> counts, double q) {
  std::uint64_t n = 0;
  for (const std::uint64_t c : counts) n += c;
  const Rank r = RankOf(static_cast<std::size_t>(n), q);
  // The values of order statistics r.i and r.i + 1: walk the cumulative counts.
  double lower = -1.0;
  std::uint64_t seen = 0;
  for (std::size_t v = 0; v < counts.size(); ++v) {
    seen += counts[v];
    if (lower < 0.0 && seen > r.i) lower = static_cast<double>(v);
    if (seen > r.i + 1 || (seen == n && seen > r.i)) {
      return Interpolate(lower, static_cast<double>(v), r.fraction);
    }
  }
  return lower;  // not reached: seen reaches n
}

double Quantile(std::span<const double> values, double q) {
  return QuantileOfSorted(SortedCopy(values), q);
}

double Quantile(std::span<const float> values, double q) {
  return QuantileOfSorted(SortedCopy(values), q);
}

double Median(std::span<const double> values) { return Quantile(values, 0.5); }

double Iqr(std::span<const double> values) {
  const std::vector<double> sorted = SortedCopy(values);
  return QuantileOfSorted(sorted, 0.75) - QuantileOfSorted(sorted, 0.25);
}

double P95(std::span<const double> values) { return Quantile(values, 0.95); }

double Mean(std::span<const double> values) {
  RequireSample(values.size());
  return Summarise(values).mean;
}

double Rms(std::span<const double> values) {
  RequireSample(values.size());
  return Summarise(values).rms;
}

double Max(std::span<const double> values) {
  RequireSample(values.size());
  return Summarise(values).max;
}

Summary Summarise(std::span<const double> values) { return SummariseSorted(SortedCopy(values)); }

Summary Summarise(std::span<const float> values) { return SummariseSorted(SortedCopy(values)); }

}  // namespace tofnav
