// SPDX-License-Identifier: BSD-3-Clause
// csaps semantics against an independent dense formulation (Green & Silverman 1994, ch. 2).
#include "tofnav/correction/smoothing_spline.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>

namespace tofnav {
namespace {

constexpr double kDenseTol = 1e-8;  // banded vs dense solve of the same problem (mm)

struct Dense {
  Eigen::VectorXd value;  // knot values
  double trace = 0.0;     // of the influence matrix
};

// min p (y - a)^T W (y - a) + (1 - p) a^T K a, K = Q R^-1 Q^T with the Green-Silverman Q (n x
// n-2) and R (tridiagonal (h_i + h_i+1) / 3, h / 6): (p W + (1 - p) K) a = p W y.
Dense DenseCsaps(const std::vector<double>& x, const std::vector<double>& y,
                 const std::vector<double>& w, double p) {
  const int n = static_cast<int>(x.size()), m = n - 2;
  Eigen::MatrixXd q = Eigen::MatrixXd::Zero(n, m), r = Eigen::MatrixXd::Zero(m, m);
  for (int j = 0; j < m; ++j) {
    const double h0 = x[j + 1] - x[j], h1 = x[j + 2] - x[j + 1];
    q(j, j) = 1.0 / h0;
    q(j + 1, j) = -1.0 / h0 - 1.0 / h1;
    q(j + 2, j) = 1.0 / h1;
    r(j, j) = (h0 + h1) / 3.0;
    if (j + 1 < m) r(j, j + 1) = r(j + 1, j) = h1 / 6.0;
  }
  const Eigen::MatrixXd k = q * r.inverse() * q.transpose();
  const Eigen::VectorXd wv = Eigen::Map<const Eigen::VectorXd>(w.data(), n);
  const Eigen::MatrixXd pw = p * wv.asDiagonal().toDenseMatrix();
  const Eigen::MatrixXd lhs = pw + (1.0 - p) * k;
  const Eigen::MatrixXd influence = lhs.ldlt().solve(pw);
  return {influence * Eigen::Map<const Eigen::VectorXd>(y.data(), n), influence.trace()};
}

std::vector<double> Sample(std::mt19937_64& rng, int n, double lo, double hi) {
  std::uniform_real_distribution<double> u(lo, hi);
  std::vector<double> v(static_cast<std::size_t>(n));
  for (double& x : v) x = u(rng);
  return v;
}

TEST(FitSmoothingSpline, MatchesADenseSolveForSeveralPAndWeights) {
  std::mt19937_64 rng(3);
  for (const int n : {3, 4, 7, 25}) {
    std::vector<double> x = Sample(rng, n, 280.0, 720.0);
    std::sort(x.begin(), x.end());
    const std::vector<double> y = Sample(rng, n, -1.0, 4.0), w = Sample(rng, n, 0.5, 3.0);
    for (const double p : {1e-7, 1e-4, 0.05, 0.6, 0.999}) {
      const SmoothingSplineResult r = FitSmoothingSpline(x, y, w, {.smoothing_p = p});
      const Dense dense = DenseCsaps(x, y, w, p);
      for (int i = 0; i < n; ++i) {
        EXPECT_NEAR(r.spline.value[static_cast<std::size_t>(i)], dense.value[i], kDenseTol)
            << "n " << n << " p " << p;
        EXPECT_NEAR(r.spline.Evaluate(x[static_cast<std::size_t>(i)]), dense.value[i], kDenseTol);
      }
      EXPECT_NEAR(r.effective_dof, dense.trace, 1e-6) << "n " << n << " p " << p;
    }
  }
}

TEST(FitSmoothingSpline, POneInterpolatesAndIsNatural) {
  const std::vector<double> x = {300, 340, 410, 450, 520, 600, 700};
  const std::vector<double> y = {0.2, 1.1, 0.7, 2.0, 2.6, 3.1, 3.9};
  const SmoothingSplineResult r = FitSmoothingSpline(x, y, {}, {.smoothing_p = 1.0});
  for (std::size_t i = 0; i < x.size(); ++i) EXPECT_NEAR(r.spline.Evaluate(x[i]), y[i], 1e-12);
  // Natural: f'' = 0 at the ends, so the second difference there vanishes to O(h).
  const auto f = [&](double at) { return r.spline.Evaluate(at); };
  constexpr double kH = 1e-3;
  EXPECT_NEAR((f(300.0 + 2 * kH) - 2 * f(300.0 + kH) + f(300.0)) / (kH * kH), 0.0, 1e-3);
  EXPECT_NEAR(r.effective_dof, 7.0, 1e-9);
  // Continuity of the first derivative at an interior knot.
  EXPECT_NEAR((f(410.0) - f(410.0 - kH)) / kH, (f(410.0 + kH) - f(410.0)) / kH, 1e-3);
}

TEST(FitSmoothingSpline, PZeroIsTheWeightedLeastSquaresLine) {
  const std::vector<double> x = {300, 350, 420, 480, 560, 700};
  const std::vector<double> y = {0.1, 1.3, 1.2, 2.5, 2.4, 4.2};
  const std::vector<double> w = {1.0, 2.0, 0.5, 1.5, 1.0, 3.0};
  const SmoothingSplineResult r = FitSmoothingSpline(x, y, w, {.smoothing_p = 0.0});
  Eigen::MatrixXd a(6, 2);
  Eigen::VectorXd b(6);
  for (int i = 0; i < 6; ++i) {
    const double s = std::sqrt(w[static_cast<std::size_t>(i)]);
    a(i, 0) = s;
    a(i, 1) = s * x[static_cast<std::size_t>(i)];
    b(i) = s * y[static_cast<std::size_t>(i)];
  }
  const Eigen::Vector2d line = a.colPivHouseholderQr().solve(b);
  for (const double at : {250.0, 300.0, 333.0, 500.0, 700.0, 800.0}) {  // also extrapolated
    EXPECT_NEAR(r.spline.Evaluate(at), line[0] + line[1] * at, 1e-9) << at;
  }
  EXPECT_NEAR(r.effective_dof, 2.0, 1e-9);
}

TEST(FitSmoothingSpline, MergesDuplicateSitesExactlyAndHandlesTinyInputs) {
  const std::vector<double> x = {300, 300, 400, 500, 500, 500, 600};
  const std::vector<double> y = {1.0, 2.0, 0.5, 3.0, 3.5, 2.5, 1.0};
  const std::vector<double> w = {1.0, 3.0, 1.0, 1.0, 1.0, 2.0, 1.0};
  const SmoothingSplineResult r = FitSmoothingSpline(x, y, w, {.smoothing_p = 0.3});
  const SmoothingSplineResult merged = FitSmoothingSpline(
      std::vector<double>{300, 400, 500, 600}, std::vector<double>{1.75, 0.5, 2.875, 1.0},
      std::vector<double>{4.0, 1.0, 4.0, 1.0}, {.smoothing_p = 0.3});
  EXPECT_EQ(r.site_count, 4);
  for (const double at : {280.0, 350.0, 455.0, 599.0, 650.0}) {
    EXPECT_NEAR(r.spline.Evaluate(at), merged.spline.Evaluate(at), 1e-12);
  }
  const SmoothingSplineResult one =
      FitSmoothingSpline(std::vector<double>{5.0, 5.0}, std::vector<double>{1.0, 3.0});
  EXPECT_DOUBLE_EQ(one.spline.Evaluate(-100.0), 2.0);
  const SmoothingSplineResult two =
      FitSmoothingSpline(std::vector<double>{0.0, 10.0}, std::vector<double>{1.0, 3.0});
  EXPECT_DOUBLE_EQ(two.spline.Evaluate(20.0), 5.0);
  EXPECT_DOUBLE_EQ(CubicSpline{}.Evaluate(3.0), 0.0);
}

TEST(FitSmoothingSpline, GcvRecoversASmoothCurveFromNoisySamples) {
  constexpr double kNoiseMm = 0.3, kRecoveryTolMm = 0.08;  // RMS vs truth, ~ sigma sqrt(dof/n)
  const auto truth = [](double d) { return 4.0 / (1.0 + std::exp(-(d - 500.0) / 40.0)); };
  std::mt19937_64 rng(9);
  std::normal_distribution<double> noise(0.0, kNoiseMm);
  std::vector<double> x, y;
  for (int i = 0; i < 1200; ++i) {
    x.push_back(300.0 + static_cast<double>(i % 401));  // 1 mm sites with repeats
    y.push_back(truth(x.back()) + noise(rng));
  }
  const SmoothingSplineResult r = FitSmoothingSpline(x, y);
  double sum2 = 0.0;
  for (double d = 300.0; d <= 700.0; d += 1.0) {
    sum2 += std::pow(r.spline.Evaluate(d) - truth(d), 2);
  }
  EXPECT_LT(std::sqrt(sum2 / 401.0), kRecoveryTolMm);
  EXPECT_GT(r.smoothing_p, 0.0);
  EXPECT_LT(r.smoothing_p, 0.01);  // a "small p", as the paper says (d in mm)
  EXPECT_GT(r.effective_dof, 4.0);
  EXPECT_LT(r.effective_dof, 40.0);
}

TEST(FitSmoothingSpline, RejectsBadInput) {
  const std::vector<double> x = {1.0, 2.0, 3.0}, y = {1.0, 2.0, 3.0};
  EXPECT_THROW(FitSmoothingSpline({}, {}), std::invalid_argument);
  EXPECT_THROW(FitSmoothingSpline(x, std::vector<double>{1.0, NAN, 2.0}), std::invalid_argument);
  EXPECT_THROW(FitSmoothingSpline(x, y, std::vector<double>{1.0, 0.0, 1.0}), std::invalid_argument);
  EXPECT_THROW(FitSmoothingSpline(x, y, {}, {.smoothing_p = 1.5}), std::invalid_argument);
  CubicSpline bad{{1.0, 1.0}, {0.0, 0.0}, {0.0, 0.0}};
  EXPECT_THROW(bad.Check(), std::invalid_argument);
}

}  // namespace
}  // namespace tofnav
