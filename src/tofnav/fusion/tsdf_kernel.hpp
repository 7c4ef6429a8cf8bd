// SPDX-License-Identifier: BSD-3-Clause
// Internal to TsdfVolume: the voxel-row update of the TSDF kernel, scalar and AVX2.
#pragma once

#include <cstdint>

#include "tofnav/fusion/pixel_lookup.hpp"

namespace tofnav {

/// Everything the voxel loop reads, as local values: the compiler then keeps them in registers
/// instead of reloading members after every store into the block.
struct KernelInputs {
  PixelLookup::Table lookup;
  const float* range_mm;  // cleaned frame, 0 = unusable
  const float* weight;    // per pixel, or nullptr for all 1
  int width, height;
  float truncation_mm, inverse_truncation, max_step_mm, max_weight;
};

/// Voxels x in [x_lo, x_hi) of one 8-voxel row of a block: voxel x is centred at
/// (px, py, pz) + x (sx, sy, sz) in `ahat` and, when the row is interpolated, seen at pixel
/// position (u, v) + x (du, dv).
struct KernelRow {
  float px, py, pz, sx, sy, sz;
  float u, v, du, dv;
  int x_lo, x_hi;
  /// Voxels farther than this from the camera are left alone: an exact cull, set to the largest
  /// range the row can read plus the truncation (see FusionFrame::IntegrateBlock) [mm].
  float cull_mm = __builtin_inff();
};

/// The interpolated rows of one block, row r = y + 8 z: KernelRow's fields per row (SoA), the
/// shared step along x and voxel range, and the rows to update (bit r of `active`).
struct BlockRows {
  float px[64], py[64], pz[64], u[64], du[64], v[64], dv[64];
  float sx, sy, sz;
  int x_lo, x_hi;
  float cull_mm;
  std::uint64_t active;
};

/// The pixel positions (u[c], v[c]) of a block's eight corner voxels c = x | y << 1 | z << 2,
/// x, y, z in {0, 1}: the points origin + 7 (x steps[0..2] + y steps[3..5] + z steps[6..8]) in
/// `ahat` (steps: the block's voxel steps along its axes), and (u[8], v[8]) of its centre
/// origin + 3.5 (steps[0..2] + steps[3..5] + steps[6..8]), NaN when unseen. False when a corner
/// is not seen.
bool ProjectCorners(const PixelLookup::Table& lookup, const float origin[3], const float steps[9],
                    float u[9], float v[9]);
/// Largest value of a cleaned range image (0 or positive, finite) over the pixels
/// [u_lo, u_hi] x [v_lo, v_hi].
float MaxRangeInBox(const float* range_mm, int width, int u_lo, int u_hi, int v_lo, int v_hi);

/// Curless & Levoy (1996) running average over one row of `tsdf` and `weight` (8 entries each);
/// returns the voxels updated. `interpolated`: use the row's pixel positions instead of
/// projecting each voxel through the lookup table.
std::int64_t UpdateRow(const KernelInputs& in, const KernelRow& row, bool interpolated,
                       bool bilinear, float* tsdf, float* weight);

/// True when this CPU runs UpdateInterpolatedRowAvx2.
bool CpuHasAvx2();
/// UpdateRow for interpolated rows, eight voxels at once; the same floating-point operations in
/// the same order as the scalar loop (no fused multiply-add), so the results are bit-identical.
std::int64_t UpdateInterpolatedRowAvx2(const KernelInputs& in, const KernelRow& row, bool bilinear,
                                       float* tsdf, float* weight);
/// ProjectCorners and MaxRangeInBox in eight lanes, bit-identical (same operations, same order).
bool ProjectCornersAvx2(const PixelLookup::Table& lookup, const float origin[3],
                        const float steps[9], float u[8], float v[8]);
float MaxRangeInBoxAvx2(const float* range_mm, int width, int u_lo, int u_hi, int v_lo, int v_hi);
/// Prefetches the lookup nodes that ProjectCornersAvx2 will read for these corners.
void PrefetchCornerNodesAvx2(const PixelLookup::Table& lookup, const float origin[3],
                             const float steps[9]);
/// UpdateInterpolatedRowAvx2 over the active rows of a block (`tsdf`, `weight`: 512 entries).
std::int64_t UpdateInterpolatedBlockAvx2(const KernelInputs& in, const BlockRows& rows,
                                         bool bilinear, float* tsdf, float* weight);

}  // namespace tofnav
