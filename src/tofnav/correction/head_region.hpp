// SPDX-License-Identifier: BSD-3-Clause
// Automatic head region of one AHAT range image: large planes and flat or small parts removed.
#pragma once

#include <cstdint>

#include "tofnav/core/image.hpp"
#include "tofnav/sensor/ahat_camera.hpp"

namespace tofnav {

/// The head is what remains of the surface once the background structures are removed:
/// 1. large planes (headframe board, table, wall): RANSAC on a pixel grid; a plane is accepted
///    when its inliers cover at least min_plane_area_mm2 and it is flat, i.e. most points within
///    3 x tolerance of it lie within tolerance (a plane: ~1; a slab through a curved head: ~1/3);
/// 2. depth-continuous connected components of the rest; a component is dropped when it is small
///    (a fragment, flying pixels) or flat (a tool plate: median distance to its own plane below
///    flat_median_mm);
/// 3. tool plates that touch the head in the image: flat planes of plate size within the kept
///    components, removed, then the components again.
struct HeadRegionOptions {
  bool enabled = true;  // false: every pixel with a range is head (the region is the whole frame)
  double plane_tolerance_mm = 4.0;
  double min_plane_area_mm2 = 12000.0;  // larger than a tool plate (~50 cm^2), smaller than a board
  double min_flat_ratio = 0.6;          // inliers within tolerance / within 3 x tolerance
  int max_planes = 3;
  int ransac_iterations = 96;
  int sample_stride_px = 4;  // the RANSAC grid
  double edge_abs_mm = 8.0;  // depth continuity: neighbours within max(abs, rel x range)
  double edge_rel = 0.03;
  /// Tool plates touching the head (after the components): smaller flat planes, searched on a
  /// twice finer grid over the kept components only.
  double plate_tolerance_mm = 3.0;
  double min_plate_area_mm2 = 1500.0;
  double min_plate_flat_ratio = 0.75;
  double plate_radius_mm = 45.0;  // a plate is judged within this distance of the hypothesis
  double min_component_area_mm2 = 1500.0;  // smaller components are fragments
  double flat_median_mm = 1.5;             // a component this close to its own plane is a plate
  void Check() const;                      // throws std::invalid_argument naming the bad field
};

struct HeadRegion {
  Image<std::uint8_t> mask;  // 1 = head (a pixel of `range_mm` > 0 kept), 0 otherwise
  int pixels = 0;
  int planes_removed = 0;
  int components_kept = 0;
  int components_dropped = 0;
};

/// The head pixels of a range image [mm] (0 = invalid; markers and their rims already set to 0).
/// Deterministic. Throws std::invalid_argument on bad options or when the sizes differ.
HeadRegion SelectHeadRegion(const Image<float>& range_mm, const AhatCamera& camera,
                            const HeadRegionOptions& options = {});

}  // namespace tofnav
