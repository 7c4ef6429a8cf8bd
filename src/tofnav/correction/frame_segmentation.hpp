// SPDX-License-Identifier: BSD-3-Clause
// Marker, transitional and head-surface areas of one AHAT frame (Sec. III-A.4).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "tofnav/core/image.hpp"
#include "tofnav/correction/head_region.hpp"
#include "tofnav/markers/marker_detection.hpp"
#include "tofnav/sensor/ahat_camera.hpp"
#include "tofnav/sensor/ahat_frame.hpp"

namespace tofnav {

enum class PixelClass : std::uint8_t {
  kOutside = 0,     // invalid range, invalid ray, or outside the region of interest
  kHead = 1,        // head surface: Eq. (4)
  kMarker = 2,      // retro-reflective marker: Eq. (2)
  kTransition = 3,  // dilated marker rim: mixed returns, dropped
};

struct SegmentationOptions {
  double marker_ab_threshold = kMarkerAbThreshold;  // AB counts: marker area
  int min_marker_area_px = 4;                       // smaller bright blobs are noise (left as head)
  int max_marker_area_px = kMaxMarkerAreaPx;
  int transition_dilation_px = 3;  // Chebyshev dilation of the marker area [px]
  /// Region of interest: valid range within [min_range_mm, max_range_mm], in the automatic head
  /// region (head_region; enabled = false: every such pixel) and, when roi_radius_mm > 0, within
  /// that radius of the head region's centroid (of the markers' centroid when the head region is
  /// off or empty; no markers either: no limit).
  double min_range_mm = 150.0;
  double max_range_mm = 1000.0;
  double roi_radius_mm = 0.0;
  HeadRegionOptions head_region;
  void Check() const;  // throws std::invalid_argument naming the bad field
};

/// The pixels of one marker (an 8-connected bright component).
struct MarkerArea {
  std::vector<Eigen::Vector2i> pixels;                         // (u, v) with a valid range
  Eigen::Vector3d centroid_in_ahat = Eigen::Vector3d::Zero();  // of the measured points [mm]
};

struct FrameSegmentation {
  Image<std::uint8_t> labels;  // PixelClass per pixel
  std::vector<MarkerArea> markers;
  int head_pixels = 0;
  HeadRegion region;  // the automatic head region (all range pixels when disabled)
};

/// Marker area = AB >= threshold (8-connected components within the area gates), transitional
/// area = its dilation minus itself, head = every other valid pixel inside the ROI (the automatic
/// head region of the range without the marker and transitional areas, then the radius).
FrameSegmentation SegmentFrame(const AhatFrame& frame, const AhatCamera& camera,
                               const SegmentationOptions& options = {});

}  // namespace tofnav
