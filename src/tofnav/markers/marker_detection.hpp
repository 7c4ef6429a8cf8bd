// SPDX-License-Identifier: BSD-3-Clause
// Retro-reflective marker detection in one AHAT frame: AB blobs, sub-pixel ray, robust range.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "tofnav/sensor/ahat_camera.hpp"
#include "tofnav/sensor/ahat_frame.hpp"

namespace tofnav {

struct MarkerDetectionOptions {
  double ab_threshold = 1280.0;  // AB counts: pixels at or above belong to blobs (IRToolTrack)
  /// Hysteresis: a blob must peak at or above this [AB counts]; 0 = ab_threshold.
  double ab_seed_threshold = 0.0;
  /// Adaptive threshold: max(ab_threshold, relative_threshold * the relative_percentile AB of
  /// the frame), 0 = off. Markers cover far less than 0.1 % of a frame, so the percentile is the
  /// bright background (close skin, walls) and the factor (dimensionless, e.g. 2) clears it.
  double relative_threshold = 0.0;
  double relative_percentile = 0.999;  // dimensionless, in (0, 1)
  int min_area_px = 3;
  int max_area_px = 4000;
  /// Marker diameters the scene may hold [mm]; with the blob's range they bound its area.
  double min_marker_diameter_mm = 6.0;
  double max_marker_diameter_mm = 16.0;
  /// Accepted blob area relative to a face-on disc of the min / max diameter at the blob's
  /// range, pi/4 (D/R)^2 f_u f_v (dimensionless). This rejects phase-wrapped ranges.
  double min_area_ratio = 0.35;
  double max_area_ratio = 2.0;
  /// Core pixels, whose ranges give the marker range: AB >= this fraction of the blob's peak
  /// (dimensionless); the AB fall-off at the rim marks mixed and grazing pixels.
  double core_ab_fraction = 0.7;
  int min_range_px = 3;  // valid range pixels a marker needs (core, else the whole blob)
  void Check() const;    // throws std::invalid_argument naming the bad field
};

/// One core pixel of a marker: its measured range, the angle of its ray from the marker ray and
/// the ray itself (zero in hand-made detections).
struct CoreSample {
  float range_mm = 0.0f;
  float angle_rad = 0.0f;
  Eigen::Vector3f ray_in_ahat = Eigen::Vector3f::Zero();  // unit pixel ray
};

/// One marker as measured, before Eq. (2) and before the radius is added: MarkerCentre()
/// (marker_centre.hpp) turns it into a centre for a given radius and (corrected) range.
struct DetectedMarker {
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();  // AB-weighted centroid (centres at integers)
  Eigen::Vector3d ray_in_ahat = Eigen::Vector3d::UnitZ();  // unit ray at `pixel` (bilinear)
  /// Unit ray at the interior-flat centroid: blob pixels at or above half the peak AB weigh 1,
  /// dimmer rim pixels by their brightness (partial coverage). The illumination fall-off across
  /// the blob does not pull it towards the image centre as it pulls `pixel` (a structure posed
  /// from these rays lies ~0.02 mm too far at 300-700 mm, from `ray_in_ahat` ~0.09 mm), but it is
  /// noisier: the stage reference (many frames on one line, Eq. 1 data) uses it, tracking does not.
  /// Zero when not computed (markers made elsewhere): ray_in_ahat stands in.
  Eigen::Vector3d reference_ray_in_ahat = Eigen::Vector3d::Zero();
  /// Trimmed mean of the core ranges [mm]: the measured surface range, input of Eq. (2).
  double surface_range_mm = 0.0;
  std::vector<CoreSample> core;  // the valid core pixels behind surface_range_mm
  double pixel_pitch_rad = 0.0;  // angle one pixel spans at the marker, 1 / sqrt(f_u f_v)
  int area_px = 0;               // blob pixels at or above the threshold
  double ab_peak = 0.0;          // counts
};

/// Counts of blobs dropped, by reason.
struct MarkerRejections {
  int area = 0;         // outside [min_area_px, max_area_px]
  int faint = 0;        // peak below the seed threshold
  int border = 0;       // touches the image border
  int invalid_ray = 0;  // the ray table is invalid at the centroid
  int no_depth = 0;     // fewer than min_range_px valid ranges
  int size_range = 0;   // area inconsistent with the range (wrapped or not a marker)
};

struct MarkerDetectionResult {
  std::vector<DetectedMarker> markers;  // in raster order of the blobs' first pixels
  double ab_threshold = 0.0;            // the threshold used [AB counts]
  int blob_count = 0;                   // connected components before the gates
  MarkerRejections rejected;
};

/// Finds retro-reflective markers: AB threshold, 8-connected components, area and size gates,
/// AB-weighted sub-pixel centroid, bilinear ray, robust range over the core (ranges of 0 and
/// >= kAhatInvalidRange are invalid). Never throws on frame content; throws
/// std::invalid_argument on bad options or when the frame's images do not match the camera.
MarkerDetectionResult LocateMarkers(const AhatFrame& frame, const AhatCamera& camera,
                                    const MarkerDetectionOptions& options = {});

}  // namespace tofnav
