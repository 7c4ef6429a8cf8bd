// SPDX-License-Identifier: BSD-3-Clause
// Internal to TsdfVolume: the interpolated voxel-row update with AVX2 (runtime dispatch).
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

#undef TOFNAV_AVX2

}  // namespace

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

std::int64_t UpdateInterpolatedBlockAvx2(const KernelInputs&, const BlockRows&, bool, float*,
                                         float*) {
  throw std::logic_error("UpdateInterpolatedBlockAvx2: not an x86-64 build");
}

}  // namespace tofnav

#endif
