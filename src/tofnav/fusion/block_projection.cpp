// SPDX-License-Identifier: BSD-3-Clause
// Internal to TsdfVolume: a block's corner projections and footprint maximum, scalar and AVX2.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>

#include "tofnav/fusion/tsdf_kernel.hpp"
#include "tofnav/fusion/tsdf_volume.hpp"

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace tofnav {
namespace {}  // namespace

bool ProjectCorners(const PixelLookup::Table& lookup, const float origin[3], const float steps[9],
                    float u[9], float v[9]) {
  // Corner c, then the centre (c = 8): the same operations in the same order as
  // ProjectCornersAvx2's lanes, and as Eigen's origin + steps * c and norm() (which sum
  // a0 + (a1 + a2)).
  for (int c = 0; c < 9; ++c) {
    const float half = 0.5f * kTsdfBlockLast;
    const float cx = c == 8 ? half : static_cast<float>(kTsdfBlockLast * (c & 1));
    const float cy = c == 8 ? half : static_cast<float>(kTsdfBlockLast * ((c >> 1) & 1));
    const float cz = c == 8 ? half : static_cast<float>(kTsdfBlockLast * (c >> 2));
    float p[3];
    for (int i = 0; i < 3; ++i)
      p[i] = origin[i] + (steps[i] * cx + (steps[3 + i] * cy + steps[6 + i] * cz));
    const float norm = std::sqrt(p[0] * p[0] + (p[1] * p[1] + p[2] * p[2]));
    const PixelLookup::Position position = lookup.Lookup(p[0], p[1], p[2], norm);
    if (c < 8 && !(position.u >= 0.0f)) return false;
    u[c] = position.u;
    v[c] = position.v;
  }
  return true;
}

float MaxRangeInBox(const float* range_mm, int width, int u_lo, int u_hi, int v_lo, int v_hi) {
  // Cleaned ranges are 0 or positive and finite, whose bit patterns order like the values: an
  // integer maximum, which the compiler vectorises (a float one it may not reorder).
  std::int32_t max_bits = 0;
  for (int v = v_lo; v <= v_hi; ++v) {
    const float* row = range_mm + v * width;
    for (int u = u_lo; u <= u_hi; ++u) {
      std::int32_t bits = 0;
      std::memcpy(&bits, row + u, sizeof(bits));
      max_bits = std::max(max_bits, bits);
    }
  }
  float max_range = 0.0f;
  std::memcpy(&max_range, &max_bits, sizeof(max_range));
  return max_range;
}

#if defined(__x86_64__)

namespace {

#define TOFNAV_AVX2 __attribute__((target("avx2"), always_inline)) inline

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
TOFNAV_AVX2 __m256 ProjectToPlane(const PixelLookup::Table& lookup, const float origin[3],
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
  const __m256 seen = ProjectToPlane(lookup, origin, steps, cx, cy, cz, a, b);
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
  const int seen = _mm256_movemask_ps(ProjectToPlane(lookup, origin, steps, cx, cy, cz, a, b));
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

#else  // not x86-64: the scalar versions only

bool ProjectCornersAvx2(const PixelLookup::Table&, const float*, const float*, float*, float*) {
  throw std::logic_error("ProjectCornersAvx2: not an x86-64 build");
}

void PrefetchCornerNodesAvx2(const PixelLookup::Table&, const float*, const float*) {}

float MaxRangeInBoxAvx2(const float*, int, int, int, int, int) {
  throw std::logic_error("MaxRangeInBoxAvx2: not an x86-64 build");
}

#endif

}  // namespace tofnav
