// SPDX-License-Identifier: BSD-3-Clause
// 8-connected components of bright AB pixels, found from row runs with a union-find.
#pragma once

#include <cstdint>
#include <vector>

#include "tofnav/core/image.hpp"

namespace tofnav {

/// Pixels [u_begin, u_end) of row v.
struct PixelRun {
  int v = 0;
  int u_begin = 0;
  int u_end = 0;
};

/// One 8-connected component; its runs are BrightBlobs::runs[first_run, first_run + run_count).
struct BrightBlob {
  int first_run = 0;
  int run_count = 0;
  int area_px = 0;
  int u_min = 0, v_min = 0, u_max = 0, v_max = 0;  // inclusive bounding box
  std::uint16_t ab_peak = 0;                       // counts
};

/// Components in raster order of their first pixel; runs grouped by component, in raster order.
struct BrightBlobs {
  std::vector<PixelRun> runs;
  std::vector<BrightBlob> blobs;
};

/// Components of the pixels with ab >= threshold (8-connectivity). Only bright pixels are touched
/// after the threshold scan, so the cost is one pass over the image plus O(bright runs).
/// @param threshold  AB counts; must be >= 1 (0 would make the whole image one component)
BrightBlobs FindBrightBlobs(const Image<std::uint16_t>& ab, std::uint16_t threshold);

}  // namespace tofnav
