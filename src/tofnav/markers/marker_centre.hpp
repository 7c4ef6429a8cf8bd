// SPDX-License-Identifier: BSD-3-Clause
// Marker centre from a detected marker's ray, corrected surface range, radius (docs/ahat.md 9.3).
#pragma once

#include <Eigen/Core>
#include <span>
#include <vector>

#include "tofnav/core/point_cloud.hpp"
#include "tofnav/markers/marker_detection.hpp"

namespace tofnav {

/// Range of a sphere's centre along the marker ray from one core pixel: a sphere of radius r
/// centred at range R meets a ray at angle a from the centre direction at
/// t = R cos a - sqrt(r^2 - R^2 sin^2 a), so R = t cos a + sqrt(r^2 - t^2 sin^2 a). r = 0 for
/// flat tape (then R = t cos a: a face-on disc). Rays beyond the silhouette (mixed pixels) clamp
/// the root to 0.
double MarkerCentreRangeMm(double surface_range_mm, double angle_rad, double radius_mm);
/// The inverse: the surface range t at angle a of a sphere centred at `centre_range_mm`.
double MarkerSurfaceRangeMm(double centre_range_mm, double angle_rad, double radius_mm);

/// Mean of `values` without the max(1, n / 8) smallest and largest (reorders them): a mixed or
/// flying pixel at either end drops, Gaussian noise keeps ~95 % efficiency, and unlike a median
/// the result is not stuck to the 1 mm steps of AHAT ranges. n = 3 gives the median.
double TrimmedMean(std::vector<double>& values);

/// Centre range [mm] of a marker: the trimmed mean over its core samples of
/// MarkerCentreRangeMm, with every sample range shifted by corrected - measured surface range.
/// A pixel reads the mean range over its footprint, which on a convex sphere exceeds the range at
/// its centre ray by (sigma^2 / 2) * Laplacian = (sigma^2 / 2) (2 r^2 - x^2) / (r^2 - x^2)^1.5
/// (x the lateral offset, sigma^2 = footprint^2 / 12 per axis); that excess is removed first.
double CentreRangeMm(const DetectedMarker& marker, double radius_mm, double corrected_range_mm);
/// The surface range (as in DetectedMarker::surface_range_mm) at which CentreRangeMm gives
/// `centre_range_mm`: the reference for the f_rf error of a marker whose true centre is known.
double SurfaceRangeForCentreMm(const DetectedMarker& marker, double radius_mm,
                               double centre_range_mm);

/// Centre in `ahat` [mm] from the detection's own surface range.
Eigen::Vector3d MarkerCentre(const DetectedMarker& marker, double radius_mm);
/// Centre in `ahat` [mm] from a surface range corrected by Eq. (2) (correction/).
Eigen::Vector3d MarkerCentre(const DetectedMarker& marker, double radius_mm,
                             double corrected_range_mm);
/// MarkerCentre of every marker, in order.
Points3d MarkerCentres(std::span<const DetectedMarker> markers, double radius_mm);

/// Moves a marker's measured ranges along their rays: surface_range_mm and every core sample
/// by `shift_mm` (a range correction such as Eq. 2's -f_rf).
void ShiftMarkerRange(DetectedMarker& marker, double shift_mm);

/// The entrance angle of flat tape with unit `normal` (either side up) along `ray` from the camera
/// (any length): arccos(|n . ray| / |ray|) [rad], 0 for a zero ray (docs/tracking.md 4).
double TapeEntranceAngleRad(const Eigen::Vector3d& normal, const Eigen::Vector3d& ray);

/// The tape's entrance-angle term on a sphere (docs/tracking.md 4): each core pixel's range
/// shortened by gain x its entrance angle, asin(D sin(alpha) / r) for a sphere of radius r whose
/// centre lies at `centre_in_ahat` (D from the camera) and a pixel whose ray is alpha off the
/// centre's, and surface_range_mm by their mean. A sphere looks alike from every side, so the
/// centre is all it needs: a tool's pose gives it with the least noise (one blob's centroid moves
/// alpha, and so beta, by 0.05 rad per 0.1 px at 700 mm). Detections without core pixels are left
/// as they are.
void ShiftSphereEntranceAngles(DetectedMarker& marker, const Eigen::Vector3d& centre_in_ahat,
                               double radius_mm, double gain_mm_per_rad);

}  // namespace tofnav
