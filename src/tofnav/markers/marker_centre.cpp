// SPDX-License-Identifier: BSD-3-Clause
// Sphere and disc marker centres along the detected ray (docs/ahat.md 9.3, docs/tracking.md 9.2).
#include "tofnav/markers/marker_centre.hpp"

#include <algorithm>
#include <cmath>

#include "tofnav/core/require.hpp"

namespace tofnav {
namespace {

// The footprint excess diverges at the silhouette; beyond this lateral offset (a fraction of the
// radius) it is held at its value there.
constexpr double kMaxLateralFraction = 0.9;

}  // namespace

double MarkerCentreRangeMm(double surface_range_mm, double angle_rad, double radius_mm) {
  const double t = surface_range_mm, r = radius_mm;
  const double lateral = t * std::sin(angle_rad);
  return t * std::cos(angle_rad) + std::sqrt(std::max(0.0, r * r - lateral * lateral));
}

double MarkerSurfaceRangeMm(double centre_range_mm, double angle_rad, double radius_mm) {
  const double big_r = centre_range_mm, r = radius_mm;
  const double lateral = big_r * std::sin(angle_rad);
  return big_r * std::cos(angle_rad) - std::sqrt(std::max(0.0, r * r - lateral * lateral));
}

double TrimmedMean(std::vector<double>& values) {
  Require(!values.empty(), "TrimmedMean: no values");
  std::sort(values.begin(), values.end());
  const std::size_t drop =
      std::min(std::max<std::size_t>(1, values.size() / 8), (values.size() - 1) / 2);
  double sum = 0.0;
  for (std::size_t i = drop; i < values.size() - drop; ++i) sum += values[i];
  return sum / static_cast<double>(values.size() - 2 * drop);
}

double CentreRangeMm(const DetectedMarker& marker, double radius_mm, double corrected_range_mm) {
  if (marker.core.empty()) return corrected_range_mm + radius_mm;  // hand-made detections
  const double shift_mm = corrected_range_mm - marker.surface_range_mm;
  const double r2 = radius_mm * radius_mm;
  std::vector<double> ranges;
  ranges.reserve(marker.core.size());
  for (const CoreSample& s : marker.core) {
    double t = s.range_mm + shift_mm;
    if (radius_mm > 0.0) {  // footprint excess on the convex sphere (a disc is flat: none)
      const double footprint_mm = t * marker.pixel_pitch_rad;
      const double x = std::min(t * std::sin(s.angle_rad), kMaxLateralFraction * radius_mm);
      const double x2 = x * x;
      t -= footprint_mm * footprint_mm / 24.0 * (2.0 * r2 - x2) / std::pow(r2 - x2, 1.5);
    }
    ranges.push_back(MarkerCentreRangeMm(t, s.angle_rad, radius_mm));
  }
  return TrimmedMean(ranges);
}

double SurfaceRangeForCentreMm(const DetectedMarker& marker, double radius_mm,
                               double centre_range_mm) {
  // CentreRangeMm grows with slope ~1 in the surface range: a few fixed-point steps converge.
  double surface_mm = centre_range_mm - radius_mm;
  for (int i = 0; i < 8; ++i) {
    const double step = centre_range_mm - CentreRangeMm(marker, radius_mm, surface_mm);
    surface_mm += step;
    if (std::abs(step) < 1e-9) break;
  }
  return surface_mm;
}

Eigen::Vector3d MarkerCentre(const DetectedMarker& marker, double radius_mm) {
  return MarkerCentre(marker, radius_mm, marker.surface_range_mm);
}

Eigen::Vector3d MarkerCentre(const DetectedMarker& marker, double radius_mm,
                             double corrected_range_mm) {
  return marker.ray_in_ahat * CentreRangeMm(marker, radius_mm, corrected_range_mm);
}

Points3d MarkerCentres(std::span<const DetectedMarker> markers, double radius_mm) {
  Points3d centres;
  centres.reserve(markers.size());
  for (const DetectedMarker& m : markers) centres.push_back(MarkerCentre(m, radius_mm));
  return centres;
}

void ShiftMarkerRange(DetectedMarker& marker, double shift_mm) {
  marker.surface_range_mm += shift_mm;
  for (CoreSample& s : marker.core) s.range_mm += static_cast<float>(shift_mm);
}

double TapeEntranceAngleRad(const Eigen::Vector3d& normal, const Eigen::Vector3d& ray) {
  const double length = ray.norm();
  if (!(length > 0.0)) return 0.0;
  return std::acos(std::min(1.0, std::abs(normal.dot(ray)) / length));
}

void ShiftSphereEntranceAngles(DetectedMarker& marker, const Eigen::Vector3d& centre_in_ahat,
                               double radius_mm, double gain_mm_per_rad) {
  if (marker.core.empty()) return;  // hand-made detections: no pixels to say where they lie
  const double centre_range_mm = centre_in_ahat.norm();
  const Eigen::Vector3d towards = centre_in_ahat / centre_range_mm;
  double sum_mm = 0.0;
  for (CoreSample& s : marker.core) {
    const double cos_alpha = std::min(1.0, towards.dot(s.ray_in_ahat.cast<double>().normalized()));
    const double sin_alpha = std::sqrt(std::max(0.0, 1.0 - cos_alpha * cos_alpha));
    const double sin_beta = std::min(1.0, centre_range_mm * sin_alpha / radius_mm);
    const double shift_mm = -gain_mm_per_rad * std::asin(sin_beta);
    s.range_mm += static_cast<float>(shift_mm);
    sum_mm += shift_mm;
  }
  marker.surface_range_mm += sum_mm / static_cast<double>(marker.core.size());
}

}  // namespace tofnav
