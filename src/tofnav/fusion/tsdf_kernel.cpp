// SPDX-License-Identifier: BSD-3-Clause
// Internal to TsdfVolume: the per-block projective TSDF update.
#include "tofnav/fusion/tsdf_kernel.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <utility>

#include "tofnav/fusion/fusion_frame.hpp"

namespace tofnav {
namespace {

// Cost per voxel decides fusion speed (about a million voxels per frame). Two measures keep it
// at a few ns: (1) within a block the voxel -> pixel map is smooth, so the eight corner voxels
// are projected exactly and the rest interpolated (two additions per voxel instead of a division
// and a table fetch); blocks where that is not accurate enough are projected voxel by voxel.
// (2) An interpolated row of eight voxels is updated in one AVX2 pass when the CPU has it.

/// Trilinear interpolation of the corner voxels' pixel positions may stand in for projecting
/// every voxel when it misses the block centre's exact projection by at most this [px]: the
/// projection is smooth, so the error is second order in the block's image size (about 0.01 px
/// for 1 mm voxels at 400 mm), far below the pixel footprint.
constexpr float kMaxInterpolationErrorPx = 0.05f;
static_assert(kTsdfBlockSide == 8, "UpdateInterpolatedRowAvx2 holds one row in eight lanes");

template <bool kInterpolated, bool kBilinear, bool kWeighted>
std::int64_t UpdateRowT(const KernelInputs in, const KernelRow row, float* __restrict tsdf,
                        float* __restrict weight) {
  std::int64_t updated = 0;
  for (int x = row.x_lo; x < row.x_hi; ++x) {
    const auto fx = static_cast<float>(x);
    const float px = row.px + fx * row.sx, py = row.py + fx * row.sy, pz = row.pz + fx * row.sz;
    const float distance = std::sqrt(px * px + py * py + pz * pz);
    if (!(distance <= row.cull_mm)) continue;  // occluded for certain
    PixelLookup::Position position{row.u + fx * row.du, row.v + fx * row.dv};
    if constexpr (!kInterpolated) {
      position = in.lookup.Lookup(px, py, pz, distance);
      if (!(position.u >= 0.0f)) continue;  // NaN: no pixel sees this voxel
    }
    // The four pixels around the projection must be valid and on one surface: near a
    // silhouette or a depth jump, any choice of pixel puts the voxel on the wrong surface (the
    // thickened silhouettes of TSDF fusion), so the frame leaves such voxels alone.
    const int u0 = std::min(static_cast<int>(position.u), in.width - 2);
    const int v0 = std::min(static_cast<int>(position.v), in.height - 2);
    const float* r = in.range_mm + v0 * in.width + u0;
    const float d00 = r[0], d10 = r[1], d01 = r[in.width], d11 = r[in.width + 1];
    const float lo = std::min(std::min(d00, d10), std::min(d01, d11));
    const float hi = std::max(std::max(d00, d10), std::max(d01, d11));
    // Occluded (far behind the observed surface), unusable or across a depth jump.
    if (hi - distance < -in.truncation_mm || lo <= 0.0f || hi - lo > in.max_step_mm) continue;
    const float fu = position.u - static_cast<float>(u0);
    const float fv = position.v - static_cast<float>(v0);
    const int nearest = (fu < 0.5f ? 0 : 1) + (fv < 0.5f ? 0 : in.width);
    float range = r[nearest];
    if constexpr (kBilinear) {
      const float top = d00 + fu * (d10 - d00);
      const float bottom = d01 + fu * (d11 - d01);
      range = top + fv * (bottom - top);
    }
    // AHAT range is radial: the signed distance along the ray is range - |p|, not a z
    // difference (docs/ahat.md section 9).
    const float sdf = range - distance;
    if (sdf < -in.truncation_mm) continue;
    float w = 1.0f;
    if constexpr (kWeighted) {
      w = in.weight[r - in.range_mm + nearest];
      if (!(w > 0.0f)) continue;
    }
    const float value = std::min(sdf * in.inverse_truncation, 1.0f);
    const float total = weight[x] + w;
    tsdf[x] = (tsdf[x] * weight[x] + value * w) / total;
    weight[x] = std::min(total, in.max_weight);
    ++updated;
  }
  return updated;
}

/// Trilinear interpolation of one corner quantity over the block, as a polynomial in
/// t = (x, y, z) / 7: q = c0 + cx tx + cy ty + cz tz + cxy tx ty + cxz tx tz + cyz ty tz +
/// cxyz tx ty tz, with the corners indexed x | y << 1 | z << 2.
struct Trilinear {
  float c0, cx, cy, cz, cxy, cxz, cyz, cxyz;
  explicit Trilinear(const float* q)
      : c0(q[0]),
        cx(q[1] - q[0]),
        cy(q[2] - q[0]),
        cz(q[4] - q[0]),
        cxy(q[3] - q[2] - q[1] + q[0]),
        cxz(q[5] - q[4] - q[1] + q[0]),
        cyz(q[6] - q[4] - q[2] + q[0]),
        cxyz(q[7] - q[6] - q[5] - q[3] + q[4] + q[2] + q[1] - q[0]) {}
  /// Value at x = 0 and change per voxel along x, on the row (ty, tz).
  std::pair<float, float> Row(float ty, float tz) const {
    return {c0 + cy * ty + cz * tz + cyz * ty * tz,
            (cx + cxy * ty + cxz * tz + cxyz * ty * tz) / kTsdfBlockLast};
  }
  /// Row(y / 7, z / 7) for the 64 rows r = y + 8 z of a block: value and change per voxel.
  void Rows(float* start, float* step) const {
    constexpr float kT[kTsdfBlockSide] = {0.0f,
                                          1.0f / kTsdfBlockLast,
                                          2.0f / kTsdfBlockLast,
                                          3.0f / kTsdfBlockLast,
                                          4.0f / kTsdfBlockLast,
                                          5.0f / kTsdfBlockLast,
                                          6.0f / kTsdfBlockLast,
                                          1.0f};
    constexpr float kPerVoxel = 1.0f / kTsdfBlockLast;
    for (int z = 0; z < kTsdfBlockSide; ++z) {
      const float tz = kT[z];
      const float start_z = c0 + cz * tz, slope_z = cy + cyz * tz;
      const float step_z = cx + cxz * tz, step_slope_z = cxy + cxyz * tz;
      for (int y = 0; y < kTsdfBlockSide; ++y) {
        start[y + kTsdfBlockSide * z] = start_z + slope_z * kT[y];
        step[y + kTsdfBlockSide * z] = (step_z + step_slope_z * kT[y]) * kPerVoxel;
      }
    }
  }
};

/// The corners' pixel positions as trilinear interpolants, and the pixels any voxel of the block
/// reads: interpolated positions are convex combinations of the corners', so a voxel's four
/// pixels lie in [u_lo, u_hi] x [v_lo, v_hi].
struct BlockProjection {
  Trilinear u, v;
  int u_lo, u_hi, v_lo, v_hi;
};

/// The projection of the block when every corner is seen and the trilinear interpolation of the
/// corners reproduces the centre voxel's projection.
std::optional<BlockProjection> InterpolatedProjection(const PixelLookup::Table& lookup,
                                                      const Eigen::Vector3f& origin,
                                                      const Eigen::Matrix3f& steps, int width,
                                                      int height, bool avx2) {
  float u[9], v[9];  // eight corners and the centre
  // origin.data(), not a copy: an array built from the coordinates would be reloaded in wider
  // pieces than it was stored in (a store-forwarding stall, measured at 3 % of fusion).
  const bool seen = avx2 ? ProjectCornersAvx2(lookup, origin.data(), steps.data(), u, v)
                         : ProjectCorners(lookup, origin.data(), steps.data(), u, v);
  if (!seen) return std::nullopt;
  const PixelLookup::Position exact{u[8], v[8]};
  const Trilinear tu(u), tv(v);
  const float mid_u = tu.Row(0.5f, 0.5f).first + 0.5f * kTsdfBlockLast * tu.Row(0.5f, 0.5f).second;
  const float mid_v = tv.Row(0.5f, 0.5f).first + 0.5f * kTsdfBlockLast * tv.Row(0.5f, 0.5f).second;
  if (!(std::abs(exact.u - mid_u) <= kMaxInterpolationErrorPx &&
        std::abs(exact.v - mid_v) <= kMaxInterpolationErrorPx)) {
    return std::nullopt;
  }
  const auto [u_min, u_max] = std::minmax_element(u, u + 8);
  const auto [v_min, v_max] = std::minmax_element(v, v + 8);
  // The kernel reads pixels min(floor(u), width - 2) and the one after. Its u and v are the
  // corners' interpolation up to rounding: the margin keeps the footprint a bound.
  constexpr float kMarginPx = 0.01f;
  const auto first = [](float p, int size) {
    return std::clamp(static_cast<int>(p - kMarginPx), 0, size - 2);
  };
  const auto last = [](float p, int size) {
    return std::min(static_cast<int>(p + kMarginPx), size - 2) + 1;
  };
  return BlockProjection{tu,
                         tv,
                         first(*u_min, width),
                         last(*u_max, width),
                         first(*v_min, height),
                         last(*v_max, height)};
}

/// Largest range in the block's pixel footprint; infinity when the footprint is too large to
/// scan cheaply (a block very near the camera).
float FootprintMaxRange(const float* range_mm, int width, const BlockProjection& p, bool avx2) {
  constexpr int kMaxScannedPixels = 1024;
  if ((p.u_hi - p.u_lo + 1) * (p.v_hi - p.v_lo + 1) > kMaxScannedPixels) return INFINITY;
  return avx2 ? MaxRangeInBoxAvx2(range_mm, width, p.u_lo, p.u_hi, p.v_lo, p.v_hi)
              : MaxRangeInBox(range_mm, width, p.u_lo, p.u_hi, p.v_lo, p.v_hi);
}

}  // namespace

std::int64_t UpdateRow(const KernelInputs& in, const KernelRow& row, bool interpolated,
                       bool bilinear, float* tsdf, float* weight) {
  const bool weighted = in.weight != nullptr;
  // One instantiation per case keeps these branches out of the voxel loop.
  if (interpolated) {
    if (bilinear) {
      return weighted ? UpdateRowT<true, true, true>(in, row, tsdf, weight)
                      : UpdateRowT<true, true, false>(in, row, tsdf, weight);
    }
    return weighted ? UpdateRowT<true, false, true>(in, row, tsdf, weight)
                    : UpdateRowT<true, false, false>(in, row, tsdf, weight);
  }
  if (bilinear) {
    return weighted ? UpdateRowT<false, true, true>(in, row, tsdf, weight)
                    : UpdateRowT<false, true, false>(in, row, tsdf, weight);
  }
  return weighted ? UpdateRowT<false, false, true>(in, row, tsdf, weight)
                  : UpdateRowT<false, false, false>(in, row, tsdf, weight);
}

std::pair<Eigen::Matrix3f, Eigen::Vector3f> FusionFrame::BlockInAhat(
    const Eigen::Vector3i& key) const {
  const Eigen::Matrix3f steps =
      static_cast<float>(options_.voxel_size_mm) * ahat_from_tool_rotation_;
  return {steps, steps * (kTsdfBlockSide * key).cast<float>() + ahat_from_tool_translation_};
}

void FusionFrame::PrefetchBlock(const Eigen::Vector3i& key) const {
  if (!use_avx2_) return;
  const auto [steps, origin] = BlockInAhat(key);
  PrefetchCornerNodesAvx2(lookup_.table(), origin.data(), steps.data());
}

std::int64_t FusionFrame::IntegrateBlock(const Eigen::Vector3i& key, TsdfBlock& block) const {
  // Voxel range of this block inside the ROI.
  const Eigen::Vector3i first = kTsdfBlockSide * key;
  const Eigen::Vector3i lo = (roi_lo_vox_ - first).cwiseMax(0);
  const Eigen::Vector3i hi =
      (roi_hi_vox_ - first + Eigen::Vector3i::Ones()).cwiseMin(kTsdfBlockSide);
  if ((lo.array() >= hi.array()).any()) return 0;

  const KernelInputs in{lookup_.table(),
                        range_mm_.data(),
                        weight_.empty() ? nullptr : weight_.data(),
                        width_,
                        height_,
                        truncation_mm_,
                        1.0f / truncation_mm_,
                        max_step_mm_,
                        static_cast<float>(options_.max_weight)};
  const auto voxel = static_cast<float>(options_.voxel_size_mm);
  const auto [steps, origin] = BlockInAhat(key);
  const auto projection =
      InterpolatedProjection(in.lookup, origin, steps, width_, height_, use_avx2_);
  // Occlusion culling, exact: a voxel is updated only when range - |p| >= -truncation, and a
  // voxel's range is at most the largest range it reads, so voxels (rows, whole blocks) farther
  // than that plus the truncation are left alone without reading the frame (most of a block
  // behind the surface). The margin absorbs rounding in the bounds.
  constexpr float kCullMarginMm = 0.01f;
  float cull_mm = INFINITY;
  if (projection) {
    cull_mm = FootprintMaxRange(in.range_mm, width_, *projection, use_avx2_) + truncation_mm_ +
              kCullMarginMm;
    const Eigen::Vector3f centre =
        origin + steps * Eigen::Vector3f::Constant(0.5f * kTsdfBlockLast);
    const float half_diagonal = 0.5f * kTsdfBlockLast * std::sqrt(3.0f) * voxel;
    if (centre.norm() - half_diagonal > cull_mm) return 0;
  }
  const bool bilinear = options_.sampling == TsdfDepthSampling::kBilinear;
  // Plain floats from here: this runs per row, also in unoptimised builds.
  const float o[3] = {origin.x(), origin.y(), origin.z()};
  const float sx[3] = {steps(0, 0), steps(1, 0), steps(2, 0)};
  const float sy[3] = {steps(0, 1), steps(1, 1), steps(2, 1)};
  const float sz[3] = {steps(0, 2), steps(1, 2), steps(2, 2)};
  // Every row's start point and pixel positions, computed once for the scalar and SIMD paths:
  // branch-free loops over all 64 rows, which the compiler vectorises.
  BlockRows rows;
  rows.sx = sx[0], rows.sy = sx[1], rows.sz = sx[2];
  rows.x_lo = lo.x(), rows.x_hi = hi.x();
  rows.cull_mm = cull_mm;
  rows.active = 0;
  for (int z = lo.z(); z < hi.z(); ++z) {
    for (int y = lo.y(); y < hi.y(); ++y)
      rows.active |= std::uint64_t{1} << (y + kTsdfBlockSide * z);
  }
  for (int z = 0; z < kTsdfBlockSide; ++z) {
    const auto fz = static_cast<float>(z);
    const float start[3] = {o[0] + fz * sz[0], o[1] + fz * sz[1], o[2] + fz * sz[2]};
    for (int y = 0; y < kTsdfBlockSide; ++y) {
      const auto fy = static_cast<float>(y);
      rows.px[y + kTsdfBlockSide * z] = start[0] + fy * sy[0];
      rows.py[y + kTsdfBlockSide * z] = start[1] + fy * sy[1];
      rows.pz[y + kTsdfBlockSide * z] = start[2] + fy * sy[2];
    }
  }
  if (projection) {
    projection->u.Rows(rows.u, rows.du);
    projection->v.Rows(rows.v, rows.dv);
  } else {
    std::fill_n(rows.u, 64, 0.0f), std::fill_n(rows.du, 64, 0.0f);
    std::fill_n(rows.v, 64, 0.0f), std::fill_n(rows.dv, 64, 0.0f);
  }
  if (projection && use_avx2_) {
    return UpdateInterpolatedBlockAvx2(in, rows, bilinear, block.tsdf.data(), block.weight.data());
  }
  std::int64_t updated = 0;
  for (std::uint64_t active = rows.active; active != 0; active &= active - 1) {
    const int r = __builtin_ctzll(active);
    const auto offset = static_cast<std::size_t>(kTsdfBlockSide * r);
    const KernelRow row{rows.px[r], rows.py[r], rows.pz[r], sx[0],  sx[1],  sx[2],  rows.u[r],
                        rows.v[r],  rows.du[r], rows.dv[r], lo.x(), hi.x(), cull_mm};
    updated += UpdateRow(in, row, projection.has_value(), bilinear, block.tsdf.data() + offset,
                         block.weight.data() + offset);
  }
  return updated;
}

}  // namespace tofnav
