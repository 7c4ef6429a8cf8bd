// SPDX-License-Identifier: BSD-3-Clause
// Cubic smoothing spline with MATLAB/Octave csaps semantics (docs/tof_physics.md section 12).
#pragma once

#include <optional>
#include <span>
#include <vector>

namespace tofnav {

/// A natural cubic spline stored by its knot values and second derivatives, extended linearly
/// outside [x.front(), x.back()]. One knot is a constant, two a line.
struct CubicSpline {
  std::vector<double> x;                  // strictly increasing sites
  std::vector<double> value;              // f(x_i)
  std::vector<double> second_derivative;  // f''(x_i); 0 at both ends (natural)
  double Evaluate(double at) const;       // 0 for an empty spline
  void Check() const;  // throws std::invalid_argument on inconsistent sizes or order
};

/// Data term weights and smoothing: csaps minimises p sum w (y - f)^2 + (1 - p) int f''^2.
struct SmoothingSplineOptions {
  /// csaps p in [0, 1]: 0 the weighted least-squares line, 1 the natural interpolant. It depends
  /// on the x unit (use mm). nullopt: chosen by GCV (Craven & Wahba 1979) after merging duplicates.
  std::optional<double> smoothing_p;
  double min_log10_lambda = -6.0;  // GCV search over lambda = (1 - p) / p (x in mm: mm^3)
  double max_log10_lambda = 14.0;
  void Check() const;  // throws std::invalid_argument naming the bad field
};

struct SmoothingSplineResult {
  CubicSpline spline;
  double smoothing_p = 1.0;    // the p used
  double effective_dof = 0.0;  // trace of the influence matrix A(p)
  double gcv_score = 0.0;      // n RSS_w / (n - tr A)^2 over the merged sites
  double rss_weighted = 0.0;   // sum w (y - f)^2 over the merged sites
  int site_count = 0;          // distinct x after merging duplicates
};

/// Fits the csaps smoothing spline (Reinsch / de Boor, O(n) banded solve). Equal x are merged
/// into one site with the weighted mean y and the summed weight (exact for a fixed p). Throws
/// std::invalid_argument on empty input, size mismatch, non-finite values or weights <= 0.
/// @param weights  w_i > 0 (inverse variances); empty = all 1
SmoothingSplineResult FitSmoothingSpline(std::span<const double> x, std::span<const double> y,
                                         std::span<const double> weights = {},
                                         const SmoothingSplineOptions& options = {});

}  // namespace tofnav
