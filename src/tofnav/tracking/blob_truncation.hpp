// SPDX-License-Identifier: BSD-3-Clause
// A marker blob that lost part of its face: how far its centroid may lie from the marker's
// centre, judged from its area against its tool's other blobs (docs/tracking.md 6).
#pragma once

#include <span>
#include <vector>

#include "tofnav/core/point_cloud.hpp"
#include "tofnav/core/rigid3d.hpp"
#include "tofnav/markers/marker_detection.hpp"
#include "tofnav/tracking/tool_geometry.hpp"

namespace tofnav {

struct BlobTruncationOptions {
  /// Give a blob smaller than its siblings an extra lateral sigma in the pose (off: every matched
  /// blob weighs as a whole one).
  bool enabled = true;
  /// Sd of a whole blob's area over its siblings' median (range^2-normalised): pixel
  /// quantisation of 10-30 pixel blobs. Measured 0.07-0.14 over 36000 whole reference-plate
  /// blobs of three spent seed sets (docs/tracking.md 6).
  double area_ratio_sd = 0.12;
  /// How many of those sds of missing area a blob is granted before it counts as truncated:
  /// fewer where detection saw something in front of or beside it (MarkerDamage::Any), more where
  /// it did not, so that the ratio's noise alone moves no whole blob.
  double damaged_grace_sds = 1.0;
  double whole_grace_sds = 2.0;
  void Check() const;  // throws std::invalid_argument naming the bad field
};

/// Centroid shift of a uniform disc of radius 1 whose part beyond a straight chord is hidden,
/// as a function of the visible fraction of its area (1: whole, 0.5: 4 / (3 pi) = 0.424).
double TruncatedDiscCentroidShift(double visible_fraction);

/// Per tool marker (`marker_detection`: an index into `detections` or -1), an extra lateral sigma
/// of its centre [mm]: the marker radius times TruncatedDiscCentroidShift of the blob's visible
/// fraction, its area times range^2 (and, for flat discs, over the cosine of its incidence at
/// `ahat_from_tool`) over the median of its plate's other matched blobs', plus the grace above.
/// 0 for unmatched markers, hand-made detections (no pixels) and where fewer than two siblings
/// compare.
std::vector<double> TruncationLateralSigmasMm(std::span<const DetectedMarker> detections,
                                              std::span<const int> marker_detection,
                                              const ToolGeometry& tool, const Points3d& centres,
                                              const Rigid3d& ahat_from_tool,
                                              const BlobTruncationOptions& options);

}  // namespace tofnav
