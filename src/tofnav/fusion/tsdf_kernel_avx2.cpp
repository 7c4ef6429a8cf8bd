// SPDX-License-Identifier: BSD-3-Clause
// Internal to TsdfVolume: the interpolated voxel-row update with AVX2 (runtime dispatch).
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>

#include "tofnav/fusion/tsdf_kernel.hpp"

#if defined(__x86_64__)
#include <immintrin.h>

namespace tofnav {

bool CpuHasAvx2() { return __builtin_cpu_supports("avx2"); }

namespace {

#define TOFNAV_AVX2 __attribute__((target("avx2"), always_inline)) inline

/// What every row of a block shares, broadcast once.
struct Lanes {
  __m256 sx, sy, sz;  // lane * step along x, per coordinate
  __m256 in_row;      // lanes x_lo <= x < x_hi
  __m256 cull_mm;     // lanes farther than this are not updated (KernelRow::cull_mm)
};

TOFNAV_AVX2 __m256 LaneIndex() {
  return _mm256_setr_ps(0.0f, 1.0f, 2.0f, 3.0f, 4.0f, 5.0f, 6.0f, 7.0f);
}

TOFNAV_AVX2 Lanes MakeLanes(float sx, float sy, float sz, int x_lo, int x_hi, float cull_mm) {
  const __m256 x = LaneIndex();
  return {_mm256_mul_ps(x, _mm256_set1_ps(sx)), _mm256_mul_ps(x, _mm256_set1_ps(sy)),
          _mm256_mul_ps(x, _mm256_set1_ps(sz)),
          _mm256_and_ps(_mm256_cmp_ps(x, _mm256_set1_ps(static_cast<float>(x_lo)), _CMP_GE_OQ),
                        _mm256_cmp_ps(x, _mm256_set1_ps(static_cast<float>(x_hi)), _CMP_LT_OQ)),
          _mm256_set1_ps(cull_mm)};
}

/// Pixels index[k] and index[k] + 1 of `image` for the eight lanes k: eight 8-byte loads and two
/// shuffles, several times cheaper than two gathers on current cores, and the same values.
TOFNAV_AVX2 void LoadPixelPairs(const float* image, __m256i index, __m256& left, __m256& right) {
  alignas(32) std::int32_t lane[8];
  _mm256_store_si256(reinterpret_cast<__m256i*>(lane), index);
  const auto pair = [image](std::int32_t i) {
    long long bits = 0;
    std::memcpy(&bits, image + i, sizeof(bits));
    return bits;
  };
  // [l0 r0 l1 r1 | l4 r4 l5 r5] and [l2 r2 l3 r3 | l6 r6 l7 r7]
  const __m256 a = _mm256_castsi256_ps(
      _mm256_set_epi64x(pair(lane[5]), pair(lane[4]), pair(lane[1]), pair(lane[0])));
  const __m256 b = _mm256_castsi256_ps(
      _mm256_set_epi64x(pair(lane[7]), pair(lane[6]), pair(lane[3]), pair(lane[2])));
  left = _mm256_shuffle_ps(a, b, 0x88);
  right = _mm256_shuffle_ps(a, b, 0xDD);
}

// The eight voxels of a block row are the eight lanes. Each step mirrors UpdateRow's scalar
// expression (same operations, same order, mul and add kept apart), so both paths agree bit for
// bit and the volume does not depend on the CPU.
TOFNAV_AVX2 int UpdateLanes(const KernelInputs& in, const Lanes& lanes, float px0, float py0,
                            float pz0, float u_start, float du, float v_start, float dv,
                            bool bilinear, float* tsdf, float* weight) {
  const __m256 x = LaneIndex();
  const __m256 px = _mm256_add_ps(_mm256_set1_ps(px0), lanes.sx);
  const __m256 py = _mm256_add_ps(_mm256_set1_ps(py0), lanes.sy);
  const __m256 pz = _mm256_add_ps(_mm256_set1_ps(pz0), lanes.sz);
  const __m256 distance = _mm256_sqrt_ps(_mm256_add_ps(
      _mm256_add_ps(_mm256_mul_ps(px, px), _mm256_mul_ps(py, py)), _mm256_mul_ps(pz, pz)));
  // Occlusion culling: lanes beyond cull_mm cannot pass the truncation test below.
  __m256 ok = _mm256_and_ps(lanes.in_row, _mm256_cmp_ps(distance, lanes.cull_mm, _CMP_LE_OQ));
  if (_mm256_movemask_ps(ok) == 0) return 0;
  const __m256 u = _mm256_add_ps(_mm256_set1_ps(u_start), _mm256_mul_ps(x, _mm256_set1_ps(du)));
  const __m256 v = _mm256_add_ps(_mm256_set1_ps(v_start), _mm256_mul_ps(x, _mm256_set1_ps(dv)));
  const __m256i u0 = _mm256_min_epi32(_mm256_cvttps_epi32(u), _mm256_set1_epi32(in.width - 2));
  const __m256i v0 = _mm256_min_epi32(_mm256_cvttps_epi32(v), _mm256_set1_epi32(in.height - 2));
  const __m256i corner = _mm256_add_epi32(_mm256_mullo_epi32(v0, _mm256_set1_epi32(in.width)), u0);
  __m256 d00, d10, d01, d11;
  LoadPixelPairs(in.range_mm, corner, d00, d10);
  LoadPixelPairs(in.range_mm + in.width, corner, d01, d11);
  const __m256 lo = _mm256_min_ps(_mm256_min_ps(d00, d10), _mm256_min_ps(d01, d11));
  const __m256 hi = _mm256_max_ps(_mm256_max_ps(d00, d10), _mm256_max_ps(d01, d11));
  const __m256 minus_truncation = _mm256_set1_ps(-in.truncation_mm);
  ok = _mm256_and_ps(ok, _mm256_cmp_ps(_mm256_sub_ps(hi, distance), minus_truncation, _CMP_GE_OQ));
  ok = _mm256_and_ps(ok, _mm256_cmp_ps(lo, _mm256_setzero_ps(), _CMP_GT_OQ));
  ok = _mm256_and_ps(
      ok, _mm256_cmp_ps(_mm256_sub_ps(hi, lo), _mm256_set1_ps(in.max_step_mm), _CMP_LE_OQ));
  const __m256 fu = _mm256_sub_ps(u, _mm256_cvtepi32_ps(u0));
  const __m256 fv = _mm256_sub_ps(v, _mm256_cvtepi32_ps(v0));
  const __m256 half = _mm256_set1_ps(0.5f);
  const __m256 right = _mm256_cmp_ps(fu, half, _CMP_GE_OQ);  // nearest column is u0 + 1
  const __m256 down = _mm256_cmp_ps(fv, half, _CMP_GE_OQ);   // nearest row is v0 + 1
  __m256 range;
  if (bilinear) {
    const __m256 top = _mm256_add_ps(d00, _mm256_mul_ps(fu, _mm256_sub_ps(d10, d00)));
    const __m256 bottom = _mm256_add_ps(d01, _mm256_mul_ps(fu, _mm256_sub_ps(d11, d01)));
    range = _mm256_add_ps(top, _mm256_mul_ps(fv, _mm256_sub_ps(bottom, top)));
  } else {
    range = _mm256_blendv_ps(_mm256_blendv_ps(d00, d10, right), _mm256_blendv_ps(d01, d11, right),
                             down);
  }
  const __m256 sdf = _mm256_sub_ps(range, distance);
  ok = _mm256_and_ps(ok, _mm256_cmp_ps(sdf, minus_truncation, _CMP_GE_OQ));
  __m256 w = _mm256_set1_ps(1.0f);
  if (in.weight != nullptr) {
    const __m256i nearest = _mm256_add_epi32(
        _mm256_add_epi32(corner,
                         _mm256_and_si256(_mm256_castps_si256(right), _mm256_set1_epi32(1))),
        _mm256_and_si256(_mm256_castps_si256(down), _mm256_set1_epi32(in.width)));
    w = _mm256_i32gather_ps(in.weight, nearest, 4);
    ok = _mm256_and_ps(ok, _mm256_cmp_ps(w, _mm256_setzero_ps(), _CMP_GT_OQ));
  }
  const int updated = _mm256_movemask_ps(ok);
  if (updated == 0) return 0;
  const __m256 value = _mm256_min_ps(_mm256_mul_ps(sdf, _mm256_set1_ps(in.inverse_truncation)),
                                     _mm256_set1_ps(1.0f));
  const __m256 old_tsdf = _mm256_loadu_ps(tsdf);
  const __m256 old_weight = _mm256_loadu_ps(weight);
  const __m256 total = _mm256_add_ps(old_weight, w);
  const __m256 new_tsdf = _mm256_div_ps(
      _mm256_add_ps(_mm256_mul_ps(old_tsdf, old_weight), _mm256_mul_ps(value, w)), total);
  const __m256 new_weight = _mm256_min_ps(total, _mm256_set1_ps(in.max_weight));
  _mm256_storeu_ps(tsdf, _mm256_blendv_ps(old_tsdf, new_tsdf, ok));
  _mm256_storeu_ps(weight, _mm256_blendv_ps(old_weight, new_weight, ok));
  return __builtin_popcount(static_cast<unsigned>(updated));
}

/// Node `index` (a float index) of a lookup table and the next node along a, interpolated at fa:
/// PixelLookup::Table::Lookup's n[0].u + fa * (n[1].u - n[0].u) (or .v) in eight lanes; NaN
/// outside `lanes`.
TOFNAV_AVX2 __m256 NodeLerp(const float* base, __m256i index, __m256 fa, __m256 lanes) {
  const __m256 nan = _mm256_set1_ps(PixelLookup::kNaN);
  const __m256 left = _mm256_mask_i32gather_ps(nan, base, index, lanes, 4);
  const __m256 right = _mm256_mask_i32gather_ps(nan, base + 2, index, lanes, 4);
  return _mm256_add_ps(left, _mm256_mul_ps(fa, _mm256_sub_ps(right, left)));
}

/// The points origin + (steps[0..2] cx + (steps[3..5] cy + steps[6..8] cz)) (Eigen's order for
/// origin + steps * c) on the lookup table's node grid (a, b), as PixelLookup::Table::Lookup
/// computes them; returns the lanes inside the grid.
TOFNAV_AVX2 __m256 PlanePosition(const PixelLookup::Table& lookup, const float origin[3],
                                 const float steps[9], __m256 cx, __m256 cy, __m256 cz, __m256& a,
                                 __m256& b) {
  __m256 p[3];
  for (int i = 0; i < 3; ++i) {
    const __m256 yz = _mm256_add_ps(_mm256_mul_ps(_mm256_set1_ps(steps[3 + i]), cy),
                                    _mm256_mul_ps(_mm256_set1_ps(steps[6 + i]), cz));
    p[i] = _mm256_add_ps(_mm256_set1_ps(origin[i]),
                         _mm256_add_ps(_mm256_mul_ps(_mm256_set1_ps(steps[i]), cx), yz));
  }
  const __m256 norm = _mm256_sqrt_ps(
      _mm256_add_ps(_mm256_mul_ps(p[0], p[0]),
                    _mm256_add_ps(_mm256_mul_ps(p[1], p[1]), _mm256_mul_ps(p[2], p[2]))));
  const __m256 s = _mm256_div_ps(_mm256_set1_ps(1.0f), _mm256_add_ps(p[2], norm));
  const __m256 inverse_step = _mm256_set1_ps(lookup.inverse_step);
  a = _mm256_mul_ps(_mm256_sub_ps(_mm256_mul_ps(p[0], s), _mm256_set1_ps(lookup.min_a)),
                    inverse_step);
  b = _mm256_mul_ps(_mm256_sub_ps(_mm256_mul_ps(p[1], s), _mm256_set1_ps(lookup.min_b)),
                    inverse_step);
  const __m256 zero = _mm256_setzero_ps();
  return _mm256_and_ps(
      _mm256_and_ps(_mm256_cmp_ps(a, zero, _CMP_GE_OQ), _mm256_cmp_ps(b, zero, _CMP_GE_OQ)),
      _mm256_and_ps(_mm256_cmp_ps(a, _mm256_set1_ps(lookup.max_a), _CMP_LT_OQ),
                    _mm256_cmp_ps(b, _mm256_set1_ps(lookup.max_b), _CMP_LT_OQ)));
}

/// The corners' multipliers of the steps (0 or 7 per axis), lane c = corner c.
TOFNAV_AVX2 void CornerLanes(__m256& cx, __m256& cy, __m256& cz) {
  const __m256 seven = _mm256_set1_ps(7.0f);
  cx = _mm256_and_ps(seven, _mm256_castsi256_ps(_mm256_setr_epi32(0, -1, 0, -1, 0, -1, 0, -1)));
  cy = _mm256_and_ps(seven, _mm256_castsi256_ps(_mm256_setr_epi32(0, 0, -1, -1, 0, 0, -1, -1)));
  cz = _mm256_and_ps(seven, _mm256_castsi256_ps(_mm256_setr_epi32(0, 0, 0, 0, -1, -1, -1, -1)));
}

/// PixelLookup::Table::Lookup of the points origin + (steps[0..2] cx + (steps[3..5] cy +
/// steps[6..8] cz)) (Eigen's order for origin + steps * c), lane by lane, with the same
/// operations in the same order; NaN in the lanes that no pixel sees.
TOFNAV_AVX2 void LookupLanes(const PixelLookup::Table& lookup, const float origin[3],
                             const float steps[9], __m256 cx, __m256 cy, __m256 cz, __m256& u,
                             __m256& v) {
  __m256 a, b;
  const __m256 seen = PlanePosition(lookup, origin, steps, cx, cy, cz, a, b);
  const __m256i ia = _mm256_cvttps_epi32(a), ib = _mm256_cvttps_epi32(b);
  const __m256 fa = _mm256_sub_ps(a, _mm256_cvtepi32_ps(ia));
  const __m256 fb = _mm256_sub_ps(b, _mm256_cvtepi32_ps(ib));
  // Nodes are (u, v) float pairs: node k's u is float 2 k, its v float 2 k + 1. Lanes outside
  // the table gather nothing (their indices are garbage).
  const __m256i n = _mm256_slli_epi32(
      _mm256_add_epi32(_mm256_mullo_epi32(ib, _mm256_set1_epi32(lookup.stride)), ia), 1);
  const __m256i m = _mm256_add_epi32(n, _mm256_set1_epi32(2 * lookup.stride));
  const float* node_u = &lookup.nodes[0].u;
  const float* node_v = &lookup.nodes[0].v;
  const __m256 u0 = NodeLerp(node_u, n, fa, seen), u1 = NodeLerp(node_u, m, fa, seen);
  const __m256 v0 = NodeLerp(node_v, n, fa, seen), v1 = NodeLerp(node_v, m, fa, seen);
  u = _mm256_add_ps(u0, _mm256_mul_ps(fb, _mm256_sub_ps(u1, u0)));
  v = _mm256_add_ps(v0, _mm256_mul_ps(fb, _mm256_sub_ps(v1, v0)));
}

#undef TOFNAV_AVX2

}  // namespace

__attribute__((target("avx2"))) bool ProjectCornersAvx2(const PixelLookup::Table& lookup,
                                                        const float origin[3], const float steps[9],
                                                        float u[9], float v[9]) {
  // Lane c is corner c.
  const __m256 zero = _mm256_setzero_ps();
  __m256 cx, cy, cz;
  CornerLanes(cx, cy, cz);
  __m256 corner_u, corner_v;
  LookupLanes(lookup, origin, steps, cx, cy, cz, corner_u, corner_v);
  // Unseen lanes are NaN, which fails the comparison.
  if (_mm256_movemask_ps(_mm256_cmp_ps(corner_u, zero, _CMP_GE_OQ)) != 0xFF) return false;
  _mm256_storeu_ps(u, corner_u);
  _mm256_storeu_ps(v, corner_v);
  // The centre: one point, scalar (a gather pass for one lane costs more).
  constexpr float kHalf = 3.5f;
  float p[3];
  for (int i = 0; i < 3; ++i)
    p[i] = origin[i] + (steps[i] * kHalf + (steps[3 + i] * kHalf + steps[6 + i] * kHalf));
  const PixelLookup::Position centre =
      lookup.Lookup(p[0], p[1], p[2], std::sqrt(p[0] * p[0] + (p[1] * p[1] + p[2] * p[2])));
  u[8] = centre.u;
  v[8] = centre.v;
  return true;
}

__attribute__((target("avx2"))) void PrefetchCornerNodesAvx2(const PixelLookup::Table& lookup,
                                                             const float origin[3],
                                                             const float steps[9]) {
  __m256 cx, cy, cz, a, b;
  CornerLanes(cx, cy, cz);
  const int seen = _mm256_movemask_ps(PlanePosition(lookup, origin, steps, cx, cy, cz, a, b));
  if (seen != 0xFF) return;
  const __m256i node =
      _mm256_add_epi32(_mm256_mullo_epi32(_mm256_cvttps_epi32(b), _mm256_set1_epi32(lookup.stride)),
                       _mm256_cvttps_epi32(a));
  alignas(32) std::int32_t lane[8];
  _mm256_store_si256(reinterpret_cast<__m256i*>(lane), node);
  for (const std::int32_t n : lane) {
    __builtin_prefetch(lookup.nodes + n);
    __builtin_prefetch(lookup.nodes + n + lookup.stride);
  }
}

__attribute__((target("avx2"))) float MaxRangeInBoxAvx2(const float* range_mm, int width, int u_lo,
                                                        int u_hi, int v_lo, int v_hi) {
  // Ranges are 0 or positive and finite: the maximum of their bit patterns is theirs, exactly.
  // The masked loads read only the pixels in the box.
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  __m256i max_bits = _mm256_setzero_si256();
  for (int v = v_lo; v <= v_hi; ++v) {
    const float* row = range_mm + v * width;
    for (int u = u_lo; u <= u_hi; u += 8) {
      const __m256i mask = _mm256_cmpgt_epi32(_mm256_set1_epi32(u_hi - u + 1), lane);
      const __m256i bits = _mm256_maskload_epi32(reinterpret_cast<const int*>(row + u), mask);
      max_bits = _mm256_max_epi32(max_bits, bits);
    }
  }
  const __m128i half =
      _mm_max_epi32(_mm256_castsi256_si128(max_bits), _mm256_extracti128_si256(max_bits, 1));
  const __m128i quarter = _mm_max_epi32(half, _mm_shuffle_epi32(half, 0x4E));
  const __m128i one = _mm_max_epi32(quarter, _mm_shuffle_epi32(quarter, 0xB1));
  return _mm_cvtss_f32(_mm_castsi128_ps(one));
}

__attribute__((target("avx2"))) std::int64_t UpdateInterpolatedRowAvx2(const KernelInputs& in,
                                                                       const KernelRow& row,
                                                                       bool bilinear, float* tsdf,
                                                                       float* weight) {
  const Lanes lanes = MakeLanes(row.sx, row.sy, row.sz, row.x_lo, row.x_hi, row.cull_mm);
  return UpdateLanes(in, lanes, row.px, row.py, row.pz, row.u, row.du, row.v, row.dv, bilinear,
                     tsdf, weight);
}

__attribute__((target("avx2"))) std::int64_t UpdateInterpolatedBlockAvx2(const KernelInputs& in,
                                                                         const BlockRows& rows,
                                                                         bool bilinear, float* tsdf,
                                                                         float* weight) {
  // A copy in locals: the stores into the block could alias `in`, which would make the compiler
  // reload (and re-broadcast) its fields for every row.
  const KernelInputs local = in;
  const Lanes lanes = MakeLanes(rows.sx, rows.sy, rows.sz, rows.x_lo, rows.x_hi, rows.cull_mm);
  std::int64_t updated = 0;
  for (std::uint64_t active = rows.active; active != 0; active &= active - 1) {
    const int r = __builtin_ctzll(active);
    const int offset = r * 8;  // eight voxels per row
    updated += UpdateLanes(local, lanes, rows.px[r], rows.py[r], rows.pz[r], rows.u[r], rows.du[r],
                           rows.v[r], rows.dv[r], bilinear, tsdf + offset, weight + offset);
  }
  return updated;
}

}  // namespace tofnav

#else  // not x86-64: the scalar loop only

namespace tofnav {

bool CpuHasAvx2() { return false; }

std::int64_t UpdateInterpolatedRowAvx2(const KernelInputs&, const KernelRow&, bool, float*,
                                       float*) {
  throw std::logic_error("UpdateInterpolatedRowAvx2: not an x86-64 build");
}

bool ProjectCornersAvx2(const PixelLookup::Table&, const float*, const float*, float*, float*) {
  throw std::logic_error("ProjectCornersAvx2: not an x86-64 build");
}

void PrefetchCornerNodesAvx2(const PixelLookup::Table&, const float*, const float*) {}

float MaxRangeInBoxAvx2(const float*, int, int, int, int, int) {
  throw std::logic_error("MaxRangeInBoxAvx2: not an x86-64 build");
}

std::int64_t UpdateInterpolatedBlockAvx2(const KernelInputs&, const BlockRows&, bool, float*,
                                         float*) {
  throw std::logic_error("UpdateInterpolatedBlockAvx2: not an x86-64 build");
}

}  // namespace tofnav

#endif
