// SPDX-License-Identifier: BSD-3-Clause
// Internal to TsdfVolume: the interpolated voxel-row update with AVX2 (runtime dispatch).
#include <stdexcept>

#include "tofnav/fusion/tsdf_kernel.hpp"

#if defined(__x86_64__)
#include <immintrin.h>

namespace tofnav {

bool CpuHasAvx2() { return __builtin_cpu_supports("avx2"); }

namespace {

/// start + lane * step for lanes 0..7.
__attribute__((target("avx2"))) inline __m256 Along(float start, float step) {
  const __m256 lane = _mm256_setr_ps(0.0f, 1.0f, 2.0f, 3.0f, 4.0f, 5.0f, 6.0f, 7.0f);
  return _mm256_add_ps(_mm256_set1_ps(start), _mm256_mul_ps(lane, _mm256_set1_ps(step)));
}

}  // namespace

// The eight voxels of a block row are the eight lanes. Each step mirrors UpdateRow's scalar
// expression (same operations, same order, mul and add kept apart), so both paths agree bit for
// bit and the volume does not depend on the CPU.
__attribute__((target("avx2"))) std::int64_t UpdateInterpolatedRowAvx2(const KernelInputs& in,
                                                                       const KernelRow& row,
                                                                       bool bilinear, float* tsdf,
                                                                       float* weight) {
  const __m256 x = Along(0.0f, 1.0f);
  const __m256 px = Along(row.px, row.sx), py = Along(row.py, row.sy), pz = Along(row.pz, row.sz);
  const __m256 distance = _mm256_sqrt_ps(_mm256_add_ps(
      _mm256_add_ps(_mm256_mul_ps(px, px), _mm256_mul_ps(py, py)), _mm256_mul_ps(pz, pz)));
  const __m256 u = Along(row.u, row.du), v = Along(row.v, row.dv);
  const __m256i u0 = _mm256_min_epi32(_mm256_cvttps_epi32(u), _mm256_set1_epi32(in.width - 2));
  const __m256i v0 = _mm256_min_epi32(_mm256_cvttps_epi32(v), _mm256_set1_epi32(in.height - 2));
  const __m256i corner = _mm256_add_epi32(_mm256_mullo_epi32(v0, _mm256_set1_epi32(in.width)), u0);
  const float* r = in.range_mm;
  const __m256 d00 = _mm256_i32gather_ps(r, corner, 4);
  const __m256 d10 = _mm256_i32gather_ps(r + 1, corner, 4);
  const __m256 d01 = _mm256_i32gather_ps(r + in.width, corner, 4);
  const __m256 d11 = _mm256_i32gather_ps(r + in.width + 1, corner, 4);
  const __m256 lo = _mm256_min_ps(_mm256_min_ps(d00, d10), _mm256_min_ps(d01, d11));
  const __m256 hi = _mm256_max_ps(_mm256_max_ps(d00, d10), _mm256_max_ps(d01, d11));
  const __m256 minus_truncation = _mm256_set1_ps(-in.truncation_mm);
  __m256 ok =
      _mm256_and_ps(_mm256_cmp_ps(x, _mm256_set1_ps(static_cast<float>(row.x_lo)), _CMP_GE_OQ),
                    _mm256_cmp_ps(x, _mm256_set1_ps(static_cast<float>(row.x_hi)), _CMP_LT_OQ));
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

}  // namespace tofnav

#else  // not x86-64: the scalar loop only

namespace tofnav {

bool CpuHasAvx2() { return false; }

std::int64_t UpdateInterpolatedRowAvx2(const KernelInputs&, const KernelRow&, bool, float*,
                                       float*) {
  throw std::logic_error("UpdateInterpolatedRowAvx2: not an x86-64 build");
}

}  // namespace tofnav

#endif
