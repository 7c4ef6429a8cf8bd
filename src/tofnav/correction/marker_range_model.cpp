// SPDX-License-Identifier: BSD-3-Clause
// f_rf fit (Eq. 1) and the retro-reflective marker range correction (Eq. 2).
#include "tofnav/correction/marker_range_model.hpp"

#include <algorithm>
#include <cmath>

#include "tofnav/core/require.hpp"
#include "tofnav/markers/marker_centre.hpp"

namespace tofnav {

double MarkerRangeModel::BiasMm(double range_mm) const {
  const std::vector<double>& x = bias_mm.x;
  if (x.size() < 2 || (range_mm >= x.front() && range_mm <= x.back())) {
    return bias_mm.Evaluate(range_mm);
  }
  // The spline's end slope rests on its last few noisy samples (it was -0.045 mm/mm on one stage
  // run, 1.4 mm off 30 mm beyond the last knot); a secant over the last 50 mm of the curve says
  // where the curve was heading without following that noise.
  constexpr double kEndSecantMm = 50.0;
  const bool below = range_mm < x.front();
  const double end = below ? x.front() : x.back();
  const double inner = below ? std::min(x.front() + kEndSecantMm, x.back())
                             : std::max(x.back() - kEndSecantMm, x.front());
  const double at_end = below ? bias_mm.value.front() : bias_mm.value.back();  // the knot's value
  const double slope = (at_end - bias_mm.Evaluate(inner)) / (end - inner);
  return at_end + slope * (range_mm - end);
}

MarkerRangeFitResult FitMarkerRangeModel(std::span<const MarkerRangeSample> samples,
                                         const SmoothingSplineOptions& options,
                                         bool fit_entrance_angle) {
  Require(!samples.empty(), "FitMarkerRangeModel: no samples");
  std::vector<double> x, y, w;
  x.reserve(samples.size()), y.reserve(samples.size()), w.reserve(samples.size());
  double min_entrance = samples.front().entrance_rad, max_entrance = min_entrance;
  for (const MarkerRangeSample& s : samples) {
    x.push_back(s.range_mm);
    y.push_back(s.error_mm);
    w.push_back(s.weight);
    min_entrance = std::min(min_entrance, s.entrance_rad);
    max_entrance = std::max(max_entrance, s.entrance_rad);
  }
  MarkerRangeFitResult result;
  result.fit = FitSmoothingSpline(x, y, w, options);
  // The spline and the entrance gain in turn (a block coordinate descent on one quadratic cost
  // given p): the gain from what the spline leaves, the spline from what the gain leaves. Both
  // share the offset, so the spline takes the mean and the gain only beta's variation.
  if (fit_entrance_angle && max_entrance - min_entrance >= kMinEntranceSpanRad) {
    constexpr int kRounds = 20;
    constexpr double kSettledMmPerRad = 1e-4;
    SmoothingSplineOptions fixed = options;
    fixed.smoothing_p = result.fit.smoothing_p;  // the GCV choice of the first fit, kept
    double gain = 0.0, mean_entrance = 0.0, weight_sum = 0.0;
    for (const MarkerRangeSample& s : samples) {
      mean_entrance += s.weight * s.entrance_rad;
      weight_sum += s.weight;
    }
    mean_entrance /= weight_sum;
    for (int round = 0; round < kRounds; ++round) {
      double num = 0.0, den = 0.0;
      for (const MarkerRangeSample& s : samples) {
        const double b = s.entrance_rad - mean_entrance;
        num += s.weight * b * (s.error_mm - result.fit.spline.Evaluate(s.range_mm));
        den += s.weight * b * b;
      }
      const double next = num / den;
      for (std::size_t i = 0; i < samples.size(); ++i)
        y[i] = samples[i].error_mm - next * (samples[i].entrance_rad - mean_entrance);
      result.fit = FitSmoothingSpline(x, y, w, fixed);
      const bool settled = std::abs(next - gain) < kSettledMmPerRad;
      gain = next;
      if (settled) break;
    }
    // f_rf(d) + g beta: the spline held the offset at the mean angle; move it to beta = 0.
    for (double& v : result.fit.spline.value) v -= gain * mean_entrance;
    result.model.entrance_gain_mm_per_rad = gain;
  }
  result.model.bias_mm = result.fit.spline;
  result.model.smoothing_p = result.fit.smoothing_p;
  double sum2 = 0.0;
  for (const MarkerRangeSample& s : samples) {
    const double e = s.error_mm - result.model.BiasMm(s.range_mm, s.entrance_rad);
    sum2 += e * e;
  }
  result.rms_residual_mm = std::sqrt(sum2 / static_cast<double>(samples.size()));
  return result;
}

double CorrectMarkerRange(double surface_range_mm, const MarkerRangeModel& model) {
  return surface_range_mm - model.BiasMm(surface_range_mm);
}

Eigen::Vector3d CorrectMarkerPoint(const Eigen::Vector3d& point_in_ahat,
                                   const MarkerRangeModel& model) {
  const double norm = point_in_ahat.norm();
  if (norm == 0.0) return point_in_ahat;
  return point_in_ahat * (CorrectMarkerRange(norm, model) / norm);
}

std::vector<DetectedMarker> CorrectMarkerRanges(std::vector<DetectedMarker> markers,
                                                const MarkerRangeModel& model) {
  for (DetectedMarker& m : markers) ShiftMarkerRange(m, -model.BiasMm(m.surface_range_mm));
  return markers;
}

void ShortenTapePoints(std::span<Eigen::Vector3d> points_in_ahat, const Eigen::Vector3d& normal,
                       double gain_mm_per_rad) {
  if (gain_mm_per_rad == 0.0) return;
  const Eigen::Vector3d n = normal.normalized();
  for (Eigen::Vector3d& p : points_in_ahat) {
    const double range = p.norm();
    if (!(range > 0.0)) continue;
    p *= (range - gain_mm_per_rad * TapeEntranceAngleRad(n, p)) / range;
  }
}

}  // namespace tofnav
