// SPDX-License-Identifier: BSD-3-Clause
// Internal to TsdfVolume: marking the blocks near a frame's points, scalar and AVX2.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace tofnav {

/// Flags over the frame's box of block keys (x fastest) and what marking a point needs, as plain
/// values for the per-pixel loop.
struct BlockMarker {
  std::uint8_t* mask;  // 1: touched; rows of concurrent tasks may set the same flag
  std::int64_t stride_y, stride_z;
  int base[3];               // key of mask entry 0
  int roi_lo[3], roi_hi[3];  // voxel index bounds of the region of interest
  float truncation_mm;       // radius of the ball around a point
  float inverse_voxel;       // voxels per mm
};

/// Marks, for every pixel i in [begin, end) with range_mm[i] > 0, each block (inside the ROI)
/// whose box of voxel centres comes within truncation_mm of points[i].
void MarkBlocks(const BlockMarker& marker, const float* range_mm,
                const std::array<float, 3>* points, std::size_t begin, std::size_t end);
/// MarkBlocks with eight pixels at once: the same flags.
void MarkBlocksAvx2(const BlockMarker& marker, const float* range_mm,
                    const std::array<float, 3>* points, std::size_t begin, std::size_t end);

}  // namespace tofnav
