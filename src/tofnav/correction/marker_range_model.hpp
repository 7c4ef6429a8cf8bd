// SPDX-License-Identifier: BSD-3-Clause
// f_rf, the retro-reflector range error (Eq. 1), and the marker range correction (Eq. 2).
#pragma once

#include <Eigen/Core>
#include <span>
#include <vector>

#include "tofnav/correction/smoothing_spline.hpp"
#include "tofnav/markers/marker_detection.hpp"
#include "tofnav/markers/marker_range_sample.hpp"

namespace tofnav {

/// f_rf(d): range error [mm] of retro-reflective material at measured surface range d [mm]
/// (Eq. 1), a cubic smoothing spline in d (mm), linear beyond its knots. The empty model is 0
/// (no correction: STTAR behaviour).
struct MarkerRangeModel {
  CubicSpline bias_mm;       // x: measured surface range [mm]; value: f_rf [mm]
  double smoothing_p = 1.0;  // csaps p of the fit, with d in mm (a record; evaluation ignores it)
  /// Beyond the paper: flat tape seen at entrance angle beta reads farther by this much per
  /// radian, on top of f_rf(d) (docs/tracking.md 4). Applied where beta is known: by tracking,
  /// once a disc tool's pose gives each disc's tilt (ToolPoseOptions). 0: range only (Eq. 1).
  double entrance_gain_mm_per_rad = 0.0;
  /// f_rf at a measured range. Beyond the knots (the stage's calibrated range) it continues with
  /// the secant over the curve's last (first) 50 mm, not the spline's end tangent
  /// (docs/tracking.md 4).
  double BiasMm(double range_mm) const;
  /// f_rf(d) + entrance_gain_mm_per_rad x beta.
  double BiasMm(double range_mm, double entrance_rad) const {
    return BiasMm(range_mm) + entrance_gain_mm_per_rad * entrance_rad;
  }
  bool empty() const { return bias_mm.x.empty(); }
  void Check() const { bias_mm.Check(); }
};

struct MarkerRangeFitResult {
  MarkerRangeModel model;
  SmoothingSplineResult fit;     // p, effective degrees of freedom, GCV score, RSS
  double rms_residual_mm = 0.0;  // over the input samples (duplicates not merged)
};

/// Eq. (1): f_rf = argmin p sum w (delta - f(d))^2 + (1 - p) int f''^2 (csaps semantics; p by
/// GCV unless options.smoothing_p is given). With `fit_entrance_angle` and samples whose entrance
/// angles span at least kMinEntranceSpanRad, delta - g beta is fitted instead, g by least squares
/// in turn with the spline until it settles (docs/tracking.md 4). Throws std::invalid_argument on
/// empty or non-finite samples or weights <= 0.
MarkerRangeFitResult FitMarkerRangeModel(std::span<const MarkerRangeSample> samples,
                                         const SmoothingSplineOptions& options = {},
                                         bool fit_entrance_angle = true);
/// The entrance angles a fit of the entrance gain needs to span (10 deg): the stage's 0-30 deg.
inline constexpr double kMinEntranceSpanRad = 0.17453292519943295;

/// Eq. (2) on a range: d' = d - f_rf(d) [mm].
double CorrectMarkerRange(double surface_range_mm, const MarkerRangeModel& model);
/// Eq. (2) on a point: M' = M (|M| - f_rf(|M|)) / |M| (the origin stays put).
Eigen::Vector3d CorrectMarkerPoint(const Eigen::Vector3d& point_in_ahat,
                                   const MarkerRangeModel& model);
/// Eq. (2) on detections: every surface_range_mm and core sample shifted by -f_rf(surface
/// range), applied before the sphere radius is added (MarkerCentre). f_rf varies by < 0.05 mm
/// over a marker's few-mm range spread, so one shift per marker suffices.
std::vector<DetectedMarker> CorrectMarkerRanges(std::vector<DetectedMarker> markers,
                                                const MarkerRangeModel& model);
/// f_rf's entrance-angle term on flat tape (docs/tracking.md 4): each point's range shortened by
/// gain x the angle between its ray (from the camera at the origin) and the tape's `normal`.
void ShortenTapePoints(std::span<Eigen::Vector3d> points_in_ahat, const Eigen::Vector3d& normal,
                       double gain_mm_per_rad);

}  // namespace tofnav
