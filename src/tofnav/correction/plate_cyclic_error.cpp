// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/correction/plate_cyclic_error.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>
#include <string>

#include "tofnav/core/statistics.hpp"

namespace tofnav {
namespace {

constexpr double kAbReference = 130.0;  // counts: ln(AB_ref / AB) as the depth model's default

void RequireFit(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument("FitPlateCyclicError: " + message);
}

std::string Mm(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f", v);
  return text;
}

}  // namespace

void PlateCyclicFitOptions::Check() const {
  if (iterations < 1) throw std::invalid_argument("PlateCyclicFitOptions: iterations must be >= 1");
  if (!(huber_k > 0.0)) throw std::invalid_argument("PlateCyclicFitOptions: huber_k must be > 0");
  if (min_samples < 10) {
    throw std::invalid_argument("PlateCyclicFitOptions: min_samples must be >= 10");
  }
  if (!(min_span_periods > 0.0)) {
    throw std::invalid_argument("PlateCyclicFitOptions: min_span_periods must be > 0");
  }
}

PlateCyclicFit FitPlateCyclicError(std::span<const PlateRangeSample> samples, double period_mm,
                                   const PlateCyclicFitOptions& options) {
  options.Check();
  RequireFit(std::isfinite(period_mm) && period_mm > 0.0, "the period must be > 0");
  RequireFit(samples.size() >= options.min_samples, std::to_string(samples.size()) +
                                                        " plate samples, fewer than " +
                                                        std::to_string(options.min_samples));
  int runs = 0;
  double lo = samples.front().plane_range_mm, hi = lo;
  for (const PlateRangeSample& s : samples) {
    RequireFit(std::isfinite(s.measured_range_mm) && std::isfinite(s.plane_range_mm) &&
                   std::isfinite(s.incidence_rad) && std::isfinite(s.ab) && s.ab > 0.0 &&
                   s.run >= 0,
               "a sample is non-finite, has AB <= 0 or a negative run");
    runs = std::max(runs, s.run + 1);
    lo = std::min(lo, s.plane_range_mm);
    hi = std::max(hi, s.plane_range_mm);
  }
  RequireFit(hi - lo >= options.min_span_periods * period_mm,
             "the plate's ranges span " + Mm(hi - lo) + " mm, under " +
                 Mm(options.min_span_periods * period_mm) + " mm (" +
                 std::to_string(options.min_span_periods) +
                 " of the period): a sinusoid and the "
                 "plate's smooth range dependence cannot be told apart");
  const auto n = static_cast<Eigen::Index>(samples.size());
  const Eigen::Index p = runs + 4;  // offsets, ln AB, theta, A cos phi, A sin phi
  Eigen::MatrixXd x = Eigen::MatrixXd::Zero(n, p);
  Eigen::VectorXd y(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const PlateRangeSample& s = samples[static_cast<std::size_t>(i)];
    x(i, s.run) = 1.0;
    x(i, runs) = std::log(kAbReference / s.ab);
    x(i, runs + 1) = s.incidence_rad;
    y(i) = s.measured_range_mm - s.plane_range_mm;
  }
  const double k_per_mm = 2.0 * std::numbers::pi / period_mm;
  CyclicRangeError cyclic{0.0, period_mm, 0.0};
  Eigen::VectorXd w = Eigen::VectorXd::Ones(n), beta = Eigen::VectorXd::Zero(p);
  Eigen::VectorXd residual(n);
  double scale = 1.0;
  for (int outer = 0; outer < 2; ++outer) {  // the phase range depends on the wiggle itself
    for (Eigen::Index i = 0; i < n; ++i) {
      const double d = cyclic.RemoveMm(samples[static_cast<std::size_t>(i)].measured_range_mm);
      x(i, runs + 2) = std::sin(k_per_mm * d);
      x(i, runs + 3) = std::cos(k_per_mm * d);
    }
    for (int it = 0; it < options.iterations; ++it) {
      const Eigen::MatrixXd xtw = x.transpose() * w.asDiagonal();
      beta = (xtw * x).ldlt().solve(xtw * y);
      residual = y - x * beta;
      std::vector<double> abs(static_cast<std::size_t>(n));
      for (Eigen::Index i = 0; i < n; ++i) abs[static_cast<std::size_t>(i)] = std::abs(residual(i));
      scale = std::max(1.4826 * Median(abs), 1e-6);
      const double c = options.huber_k * scale;
      for (Eigen::Index i = 0; i < n; ++i) {
        w(i) = std::abs(residual(i)) <= c ? 1.0 : c / std::abs(residual(i));
      }
    }
    cyclic.amplitude_mm = std::hypot(beta(runs + 2), beta(runs + 3));
    cyclic.phase_rad = std::atan2(beta(runs + 3), beta(runs + 2));
  }
  PlateCyclicFit fit;
  fit.cyclic = cyclic;
  fit.run_offsets_mm.assign(beta.data(), beta.data() + runs);
  fit.intensity_mm = beta(runs);
  fit.incidence_mm_per_rad = beta(runs + 1);
  fit.robust_sd_mm = scale;
  fit.samples = samples.size();
  fit.span_mm = hi - lo;
  // Standard errors: sigma^2 (X^T W X)^-1 with the weighted residual variance, then the delta
  // method from (a, b) = (A cos phi, A sin phi) to A and phi.
  const Eigen::MatrixXd xtw = x.transpose() * w.asDiagonal();
  const double dof = std::max<double>(1.0, static_cast<double>(n - p));
  const double sigma2 = (w.array() * residual.array().square()).sum() / dof;
  const Eigen::MatrixXd cov = sigma2 * (xtw * x).ldlt().solve(Eigen::MatrixXd::Identity(p, p));
  const Eigen::Matrix2d ab_cov = cov.block(runs + 2, runs + 2, 2, 2);
  const double a = beta(runs + 2), b = beta(runs + 3), amp = std::max(cyclic.amplitude_mm, 1e-12);
  const Eigen::Vector2d d_amp(a / amp, b / amp), d_phase(-b / (amp * amp), a / (amp * amp));
  fit.amplitude_sd_mm = std::sqrt(std::max(0.0, d_amp.dot(ab_cov * d_amp)));
  fit.phase_sd_rad = std::sqrt(std::max(0.0, d_phase.dot(ab_cov * d_phase)));
  return fit;
}

}  // namespace tofnav
