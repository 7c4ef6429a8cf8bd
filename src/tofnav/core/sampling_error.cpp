// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/core/sampling_error.hpp"

#include <cmath>
#include <string>
#include <vector>

#include "tofnav/core/require.hpp"

namespace tofnav {

double RmsStandardError(std::span<const double> series) {
  const std::size_t n = series.size();
  Require(n >= 4, "an RMS's standard error needs at least 4 values, got " + std::to_string(n));
  std::vector<double> squares(n);
  double mean_square = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    Require(!std::isnan(series[i]), "NaN at index " + std::to_string(i));
    squares[i] = series[i] * series[i];
    mean_square += squares[i];
  }
  mean_square /= static_cast<double>(n);
  if (mean_square == 0.0) return 0.0;
  // Overlapping batch means (Meketon and Schmeiser): every window of b consecutive squares; their
  // spread about the overall mean, scaled by n b / ((n - b + 1)(n - b)), estimates the long-run
  // variance n Var(mean), which counts the series' correlation over up to about b samples.
  const auto b = static_cast<std::size_t>(std::lround(std::sqrt(static_cast<double>(n))));
  double window = 0.0;
  for (std::size_t i = 0; i < b; ++i) window += squares[i];
  double spread = 0.0;
  for (std::size_t j = 0; j + b <= n; ++j) {
    if (j > 0) window += squares[j + b - 1] - squares[j - 1];
    const double d = window / static_cast<double>(b) - mean_square;
    spread += d * d;
  }
  const auto nd = static_cast<double>(n), bd = static_cast<double>(b);
  const double long_run_variance = nd * bd * spread / ((nd - bd + 1.0) * (nd - bd));
  const double mean_square_se = std::sqrt(long_run_variance / nd);
  return mean_square_se / (2.0 * std::sqrt(mean_square));
}

double ExpectedRangeOfNormals(int k) {
  Require(k >= 2, "the range of k draws needs k >= 2, got " + std::to_string(k));
  // E[range] = integral over x of 1 - Phi(x)^k - (1 - Phi(x))^k (Tippett 1925); the integrand is
  // below 1e-15 beyond |x| = 9 for k <= 10^4. Simpson's rule, 3600 intervals.
  constexpr double kLimit = 9.0;
  constexpr int kIntervals = 3600;
  const double h = 2.0 * kLimit / kIntervals;
  double sum = 0.0;
  for (int i = 0; i <= kIntervals; ++i) {
    const double x = -kLimit + h * i;
    const double phi = 0.5 * std::erfc(-x / std::sqrt(2.0));
    const double f = 1.0 - std::pow(phi, k) - std::pow(1.0 - phi, k);
    const double weight = (i == 0 || i == kIntervals) ? 1.0 : (i % 2 == 1 ? 4.0 : 2.0);
    sum += weight * f;
  }
  return sum * h / 3.0;
}

}  // namespace tofnav
