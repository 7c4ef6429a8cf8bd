// SPDX-License-Identifier: BSD-3-Clause
// f_rf fit (Eq. 1) and the retro-reflective marker range correction (Eq. 2).
#include "tofnav/correction/marker_range_model.hpp"

#include <cmath>

#include "tofnav/core/require.hpp"

namespace tofnav {

MarkerRangeFitResult FitMarkerRangeModel(std::span<const MarkerRangeSample> samples,
                                         const SmoothingSplineOptions& options) {
  Require(!samples.empty(), "FitMarkerRangeModel: no samples");
  std::vector<double> x, y, w;
  x.reserve(samples.size()), y.reserve(samples.size()), w.reserve(samples.size());
  for (const MarkerRangeSample& s : samples) {
    x.push_back(s.range_mm);
    y.push_back(s.error_mm);
    w.push_back(s.weight);
  }
  MarkerRangeFitResult result;
  result.fit = FitSmoothingSpline(x, y, w, options);
  result.model.bias_mm = result.fit.spline;
  result.model.smoothing_p = result.fit.smoothing_p;
  double sum2 = 0.0;
  for (const MarkerRangeSample& s : samples) {
    const double e = s.error_mm - result.model.BiasMm(s.range_mm);
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
  for (DetectedMarker& m : markers) {
    const double shift_mm = -model.BiasMm(m.surface_range_mm);
    m.surface_range_mm += shift_mm;
    for (CoreSample& s : m.core) s.range_mm += static_cast<float>(shift_mm);
  }
  return markers;
}

}  // namespace tofnav
