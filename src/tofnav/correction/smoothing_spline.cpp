// SPDX-License-Identifier: BSD-3-Clause
// csaps: Reinsch's banded system, its influence-matrix trace (Hutchinson & de Hoog 1985) and GCV.
#include "tofnav/correction/smoothing_spline.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "tofnav/core/require.hpp"

namespace tofnav {
namespace {

struct Sites {
  std::vector<double> x, y, w;
};

// Sorts by x and merges equal x: weighted mean y, summed weight (docs/tof_physics.md 12.4).
Sites MergeSites(std::span<const double> x, std::span<const double> y,
                 std::span<const double> weights) {
  std::vector<std::size_t> order(x.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return x[a] < x[b]; });
  Sites s;
  for (const std::size_t i : order) {
    const double w = weights.empty() ? 1.0 : weights[i];
    if (!s.x.empty() && s.x.back() == x[i]) {
      s.y.back() = (s.y.back() * s.w.back() + y[i] * w) / (s.w.back() + w);
      s.w.back() += w;
    } else {
      s.x.push_back(x[i]);
      s.y.push_back(y[i]);
      s.w.push_back(w);
    }
  }
  return s;
}

// Symmetric pentadiagonal matrix: diagonal, first and second sub-diagonals (k0[j] = M_jj,
// k1[j] = M_{j+1,j}, k2[j] = M_{j+2,j}).
struct Band {
  std::vector<double> k0, k1, k2;
};

// The csaps system of docs/tof_physics.md 12.3 over m = n - 2 interior knots: R, B = Q^T W^-1 Q and
// Q^T y are built once; Solve(p) factors M = 6 (1 - p) B + p R = L D L^T.
class ReinschSystem {
 public:
  explicit ReinschSystem(const Sites& s) : s_(s), n_(s.x.size()), m_(n_ - 2) {
    std::vector<double> h(n_ - 1);
    for (std::size_t i = 0; i + 1 < n_; ++i) h[i] = s.x[i + 1] - s.x[i];
    q0_.resize(m_), q1_.resize(m_), q2_.resize(m_);
    for (std::size_t j = 0; j < m_; ++j) {
      q0_[j] = 1.0 / h[j];
      q2_[j] = 1.0 / h[j + 1];
      q1_[j] = -(q0_[j] + q2_[j]);
    }
    r_ = {std::vector<double>(m_), std::vector<double>(m_, 0.0), std::vector<double>(m_, 0.0)};
    b_ = r_;
    qty_.resize(m_);
    for (std::size_t j = 0; j < m_; ++j) {
      r_.k0[j] = 2.0 * (h[j] + h[j + 1]);
      if (j + 1 < m_) r_.k1[j] = h[j + 1];
      b_.k0[j] =
          q0_[j] * q0_[j] / s.w[j] + q1_[j] * q1_[j] / s.w[j + 1] + q2_[j] * q2_[j] / s.w[j + 2];
      if (j + 1 < m_)
        b_.k1[j] = q1_[j] * q0_[j + 1] / s.w[j + 1] + q2_[j] * q1_[j + 1] / s.w[j + 2];
      if (j + 2 < m_) b_.k2[j] = q2_[j] * q0_[j + 2] / s.w[j + 2];
      qty_[j] = q0_[j] * s.y[j] + q1_[j] * s.y[j + 1] + q2_[j] * s.y[j + 2];
    }
  }

  // Knot values a, second derivatives c and tr A(p).
  void Solve(double p, std::vector<double>& a, std::vector<double>& c, double& trace) {
    Factor(p);
    // L z = Q^T y, D, L^T u = z.
    std::vector<double> u(qty_);
    for (std::size_t i = 0; i < m_; ++i) {
      if (i >= 1) u[i] -= l1_[i] * u[i - 1];
      if (i >= 2) u[i] -= l2_[i] * u[i - 2];
    }
    for (std::size_t i = 0; i < m_; ++i) u[i] /= d_[i];
    for (std::size_t i = m_; i-- > 0;) {
      if (i + 1 < m_) u[i] -= l1_[i + 1] * u[i + 1];
      if (i + 2 < m_) u[i] -= l2_[i + 2] * u[i + 2];
    }
    a.assign(n_, 0.0);
    c.assign(n_, 0.0);
    for (std::size_t i = 0; i < n_; ++i) {
      double qu = 0.0;  // (Q u)_i
      if (i < m_) qu += q0_[i] * u[i];
      if (i >= 1 && i - 1 < m_) qu += q1_[i - 1] * u[i - 1];
      if (i >= 2 && i - 2 < m_) qu += q2_[i - 2] * u[i - 2];
      a[i] = s_.y[i] - 6.0 * (1.0 - p) / s_.w[i] * qu;
    }
    for (std::size_t j = 0; j < m_; ++j) c[j + 1] = 6.0 * p * u[j];
    trace = static_cast<double>(n_) - 6.0 * (1.0 - p) * TraceOfInverseTimesB();
  }

 private:
  void Factor(double p) {
    d_.assign(m_, 0.0), l1_.assign(m_ + 1, 0.0), l2_.assign(m_ + 2, 0.0);
    const double fb = 6.0 * (1.0 - p);
    for (std::size_t i = 0; i < m_; ++i) {
      double di = fb * b_.k0[i] + p * r_.k0[i];
      if (i >= 1) di -= l1_[i] * l1_[i] * d_[i - 1];
      if (i >= 2) di -= l2_[i] * l2_[i] * d_[i - 2];
      d_[i] = di;
      if (i + 1 < m_) {
        double m10 = fb * b_.k1[i] + p * r_.k1[i];
        if (i >= 1) m10 -= l2_[i + 1] * l1_[i] * d_[i - 1];
        l1_[i + 1] = m10 / di;
      }
      if (i + 2 < m_) l2_[i + 2] = fb * b_.k2[i] / di;
    }
  }

  // tr(M^-1 B) from the band of Z = M^-1 (Takahashi recurrences on L D L^T).
  double TraceOfInverseTimesB() const {
    std::vector<double> z0(m_ + 2, 0.0), z1(m_ + 2, 0.0),
        z2(m_ + 2, 0.0);  // Z_ii, Z_i,i+1, Z_i,i+2
    double trace = 0.0;
    for (std::size_t i = m_; i-- > 0;) {
      const double a1 = i + 1 < m_ ? l1_[i + 1] : 0.0, a2 = i + 2 < m_ ? l2_[i + 2] : 0.0;
      z2[i] = -a1 * z1[i + 1] - a2 * z0[i + 2];
      z1[i] = -a1 * z0[i + 1] - a2 * z1[i + 1];
      z0[i] = 1.0 / d_[i] - a1 * z1[i] - a2 * z2[i];
      trace += z0[i] * b_.k0[i] + 2.0 * z1[i] * b_.k1[i] + 2.0 * z2[i] * b_.k2[i];
    }
    return trace;
  }

  const Sites& s_;
  std::size_t n_, m_;
  std::vector<double> q0_, q1_, q2_, qty_;
  Band r_, b_;
  std::vector<double> d_, l1_, l2_;
};

SmoothingSplineResult Evaluate(ReinschSystem& system, const Sites& s, double p) {
  SmoothingSplineResult r;
  r.smoothing_p = p;
  r.site_count = static_cast<int>(s.x.size());
  r.spline.x = s.x;
  system.Solve(p, r.spline.value, r.spline.second_derivative, r.effective_dof);
  for (std::size_t i = 0; i < s.x.size(); ++i) {
    const double e = s.y[i] - r.spline.value[i];
    r.rss_weighted += s.w[i] * e * e;
  }
  const double n = static_cast<double>(s.x.size()), free = n - r.effective_dof;
  r.gcv_score = free > 0.0 ? n * r.rss_weighted / (free * free) : INFINITY;
  return r;
}

double PFromLog10Lambda(double log10_lambda) { return 1.0 / (1.0 + std::pow(10.0, log10_lambda)); }

// GCV over a log10(lambda) grid, refined by golden-section search around the best node.
SmoothingSplineResult SelectByGcv(ReinschSystem& system, const Sites& s,
                                  const SmoothingSplineOptions& options) {
  constexpr double kStep = 0.25;
  const auto score = [&](double l) { return Evaluate(system, s, PFromLog10Lambda(l)).gcv_score; };
  double best_l = options.min_log10_lambda, best = score(best_l);
  for (double l = options.min_log10_lambda + kStep; l <= options.max_log10_lambda + 1e-9;
       l += kStep) {
    const double v = score(l);
    if (v < best) best = v, best_l = l;
  }
  double lo = std::max(options.min_log10_lambda, best_l - kStep);
  double hi = std::min(options.max_log10_lambda, best_l + kStep);
  const double g = (std::sqrt(5.0) - 1.0) / 2.0;
  double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo), f1 = score(x1), f2 = score(x2);
  for (int i = 0; i < 40; ++i) {
    if (f1 < f2) {
      hi = x2, x2 = x1, f2 = f1, x1 = hi - g * (hi - lo), f1 = score(x1);
    } else {
      lo = x1, x1 = x2, f1 = f2, x2 = lo + g * (hi - lo), f2 = score(x2);
    }
  }
  const double l = std::min(f1, f2) < best ? (f1 < f2 ? x1 : x2) : best_l;
  return Evaluate(system, s, PFromLog10Lambda(l));
}

}  // namespace

double CubicSpline::Evaluate(double at) const {
  const std::size_t n = x.size();
  if (n == 0) return 0.0;
  if (n == 1) return value[0];
  const auto slope = [&](std::size_t i) {  // f' at the start of interval i
    const double h = x[i + 1] - x[i];
    return (value[i + 1] - value[i]) / h -
           h * (2.0 * second_derivative[i] + second_derivative[i + 1]) / 6.0;
  };
  if (at <= x[0]) return value[0] + slope(0) * (at - x[0]);
  if (at >= x[n - 1]) {
    const double h = x[n - 1] - x[n - 2];
    const double end_slope =
        slope(n - 2) + h * (second_derivative[n - 2] + second_derivative[n - 1]) / 2.0;
    return value[n - 1] + end_slope * (at - x[n - 1]);
  }
  const std::size_t i =
      static_cast<std::size_t>(std::upper_bound(x.begin(), x.end(), at) - x.begin()) - 1;
  const double h = x[i + 1] - x[i], t = at - x[i];
  const double ci = second_derivative[i], cj = second_derivative[i + 1];
  return value[i] + slope(i) * t + ci / 2.0 * t * t + (cj - ci) / (6.0 * h) * t * t * t;
}

void CubicSpline::Check() const {
  Require(value.size() == x.size() && second_derivative.size() == x.size(),
          "CubicSpline: x, value and second_derivative sizes differ");
  for (std::size_t i = 0; i < x.size(); ++i) {
    Require(std::isfinite(x[i]) && std::isfinite(value[i]) && std::isfinite(second_derivative[i]),
            "CubicSpline: non-finite entry");
    Require(i == 0 || x[i] > x[i - 1], "CubicSpline: x must be strictly increasing");
  }
}

void SmoothingSplineOptions::Check() const {
  Require(!smoothing_p || (*smoothing_p >= 0.0 && *smoothing_p <= 1.0),
          "SmoothingSplineOptions::smoothing_p must be in [0, 1]");
  Require(std::isfinite(min_log10_lambda) && std::isfinite(max_log10_lambda) &&
              min_log10_lambda < max_log10_lambda,
          "SmoothingSplineOptions::min_log10_lambda must be < max_log10_lambda");
}

SmoothingSplineResult FitSmoothingSpline(std::span<const double> x, std::span<const double> y,
                                         std::span<const double> weights,
                                         const SmoothingSplineOptions& options) {
  options.Check();
  Require(!x.empty() && x.size() == y.size(),
          "FitSmoothingSpline: x and y must be equal, non-empty");
  Require(weights.empty() || weights.size() == x.size(), "FitSmoothingSpline: bad weights size");
  for (std::size_t i = 0; i < x.size(); ++i) {
    Require(std::isfinite(x[i]) && std::isfinite(y[i]), "FitSmoothingSpline: non-finite sample");
    Require(weights.empty() || (std::isfinite(weights[i]) && weights[i] > 0.0),
            "FitSmoothingSpline: weights must be finite and > 0");
  }
  const Sites s = MergeSites(x, y, weights);
  if (s.x.size() <= 2) {  // a constant or the line through both sites, whatever p
    SmoothingSplineResult r;
    r.spline = {s.x, s.y, std::vector<double>(s.x.size(), 0.0)};
    r.smoothing_p = options.smoothing_p.value_or(1.0);
    r.effective_dof = static_cast<double>(s.x.size());
    r.site_count = static_cast<int>(s.x.size());
    return r;
  }
  ReinschSystem system(s);
  if (options.smoothing_p) return Evaluate(system, s, *options.smoothing_p);
  return SelectByGcv(system, s, options);
}

}  // namespace tofnav
