// SPDX-License-Identifier: BSD-3-Clause
// Retro-reflective marker detection in one AHAT frame: AB blobs, sub-pixel ray, robust range.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "tofnav/sensor/ahat_camera.hpp"
#include "tofnav/sensor/ahat_frame.hpp"

namespace tofnav {

/// AB counts at or above which a pixel belongs to a retro-reflective marker (IRToolTrack's
/// threshold): the one default of detection, segmentation, the CLI and the Python bindings.
inline constexpr double kMarkerAbThreshold = 1280.0;
/// Largest bright blob taken for a marker [px].
inline constexpr int kMaxMarkerAreaPx = 4000;

struct MarkerDetectionOptions {
  double ab_threshold = kMarkerAbThreshold;  // AB counts: pixels at or above belong to blobs
  /// Hysteresis: a blob must peak at or above this [AB counts]; 0 = ab_threshold.
  double ab_seed_threshold = 0.0;
  /// Adaptive threshold: max(ab_threshold, relative_threshold * the relative_percentile AB of
  /// the frame), 0 = off. Markers cover far less than 0.1 % of a frame, so the percentile is the
  /// bright background (close skin, walls) and the factor (dimensionless, e.g. 2) clears it.
  double relative_threshold = 0.0;
  double relative_percentile = 0.999;  // dimensionless, in (0, 1)
  int min_area_px = 3;
  int max_area_px = kMaxMarkerAreaPx;
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
  /// Damage checks (docs/tracking.md section 6). A blob is `merged` when its length, 4 sqrt of
  /// the largest second moment of its pixels (a uniform disc's diameter), exceeds the
  /// max_marker_diameter_mm at its range by more than this [px]: no single marker is that long.
  double merged_margin_px = 2.0;
  /// A blob is `near_blob` when another blob's pixel lies within this many pixels of its own
  /// (Chebyshev): the neighbour's spill and mixed rim pixels bias its centroid.
  int near_blob_gap_px = 2;
  /// A ring pixel (Chebyshev distance d from the blob in occluder_ring_inner_px ..
  /// occluder_ring_outer_px) is an occluder when its range is shorter than the marker's surface
  /// range by more than occluder_margin_mm + d * pixel pitch * tan(55 deg) [mm]: something in
  /// front, not the marker's own tool plate (tilted up to the tape's 55 deg cut-off, it rises by at
  /// most that much over d pixels), nor range noise, nor the tape's own long reading (f_rf up to
  /// 4 mm, and 2 mm more at 55 deg from its entrance-angle term, docs/tracking.md 4: 10 mm let a
  /// 55 deg plate through before session 28's calibrated tape, 12 mm does with it). Pixels 1-2 px
  /// from the blob hold some of the
  /// marker's light: a phasor mix of it and a far background reads any range, shorter ones too
  /// (the 1055 mm ambiguity), so they are not looked at.
  double occluder_margin_mm = 12.0;
  int occluder_ring_inner_px = 3;
  int occluder_ring_outer_px = 4;
  int min_occluder_px = 2;  // occluder pixels that make a blob `occluded` (one may be a flier)
  void Check() const;       // throws std::invalid_argument naming the bad field
};

/// Damage of a kept marker (docs/tracking.md section 6): the blob may not be the whole marker.
struct MarkerDamage {
  bool occluded = false;   // part of its rim borders pixels clearly nearer (a hand, a rod)
  bool near_blob = false;  // another blob within near_blob_gap_px
  int occluder_px = 0;     // ring pixels clearly nearer than the marker
  int ring_px = 0;         // ring pixels (occluder ring) with a valid range
  bool Any() const { return occluded || near_blob; }
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
  MarkerDamage damage;           // usable, but perhaps not whole: the tracker decides
};

/// Why a blob was dropped as a marker although it looked like one (docs/tracking.md section 6).
enum class BlobDropReason {
  kImageBorder,  // cut by the image border or the edge of the lit field: centroid biased
  kMerged,       // two or more markers fused: its centroid lies between them, its range mixes
};
const char* ToString(BlobDropReason reason);

/// A dropped blob, so that a tracker can say why a tool marker there was not used.
struct DroppedBlob {
  BlobDropReason reason = BlobDropReason::kImageBorder;
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();        // mean of its pixels
  Eigen::Vector3d ray_in_ahat = Eigen::Vector3d::Zero();  // unit ray at `pixel`; zero if invalid
  double radius_rad = 0.0;  // angular radius of a disc of its area (zero without a ray)
};

/// Counts of blobs dropped, by reason.
struct MarkerRejections {
  int area = 0;         // outside [min_area_px, max_area_px]
  int faint = 0;        // peak below the seed threshold
  int border = 0;       // touches the image border or the field's edge (also in `dropped`)
  int merged = 0;       // longer than one marker (also in MarkerDetectionResult::dropped)
  int invalid_ray = 0;  // the ray table is invalid at the centroid
  int no_depth = 0;     // fewer than min_range_px valid ranges
  int size_range = 0;   // area inconsistent with the range (wrapped or not a marker)
};

struct MarkerDetectionResult {
  std::vector<DetectedMarker> markers;  // in raster order of the blobs' first pixels
  double ab_threshold = 0.0;            // the threshold used [AB counts]
  int blob_count = 0;                   // connected components before the gates
  MarkerRejections rejected;
  std::vector<DroppedBlob> dropped;  // border and merged blobs, in raster order
};

/// Finds retro-reflective markers: AB threshold, 8-connected components, area and size gates,
/// AB-weighted sub-pixel centroid, bilinear ray, robust range over the core (ranges of 0 and
/// >= kAhatInvalidRange are invalid), damage flags (border and merged blobs dropped, occluded
/// and near ones flagged; docs/tracking.md section 6). Never throws on frame content; throws
/// std::invalid_argument on bad options or when the frame's images do not match the camera.
MarkerDetectionResult LocateMarkers(const AhatFrame& frame, const AhatCamera& camera,
                                    const MarkerDetectionOptions& options = {});

}  // namespace tofnav
