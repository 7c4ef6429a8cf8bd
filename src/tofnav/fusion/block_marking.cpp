// SPDX-License-Identifier: BSD-3-Clause
// Internal to TsdfVolume: marking the blocks near a frame's points, scalar and AVX2.
#include "tofnav/fusion/block_marking.hpp"

#include <algorithm>
#include <atomic>
#include <stdexcept>

#include "tofnav/fusion/tsdf_volume.hpp"

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace tofnav {
namespace {

static_assert(sizeof(std::array<float, 3>) == 3 * sizeof(float), "points are packed xyz");
static_assert(kTsdfBlockSide == 8, "a voxel index's block is index >> 3");

// Rounding of coordinates that fit in an int (FusionFrame::Prepare checks the key range).
int FloorToInt(float x) {
  const int i = static_cast<int>(x);  // towards zero
  return static_cast<float>(i) > x ? i - 1 : i;
}
int CeilToInt(float x) {
  const int i = static_cast<int>(x);
  return static_cast<float>(i) < x ? i + 1 : i;
}

/// Sets the flags of blocks b0 .. b1 (inclusive, relative to the mask's base).
void MarkBox(const BlockMarker& m, const int b0[3], const int b1[3]) {
  for (int z = b0[2]; z <= b1[2]; ++z) {
    for (int y = b0[1]; y <= b1[1]; ++y) {
      for (int x = b0[0]; x <= b1[0]; ++x) {
        const auto i = static_cast<std::size_t>(x + m.stride_y * y + m.stride_z * z);
        // Concurrent rows may mark the same block: a relaxed store of the same value.
        std::atomic_ref<std::uint8_t>(m.mask[i]).store(1, std::memory_order_relaxed);
      }
    }
  }
}

}  // namespace

void MarkBlocks(const BlockMarker& m, const float* range_mm, const std::array<float, 3>* points,
                std::size_t begin, std::size_t end) {
  // Blocks are 8 voxels: a voxel index's block is index >> 3 (floor division).
  int last_b0[3] = {1, 1, 1}, last_b1[3] = {0, 0, 0};  // an empty box
  for (std::size_t i = begin; i < end; ++i) {
    if (range_mm[i] <= 0.0f) continue;
    int b0[3], b1[3];
    for (std::size_t a = 0; a < 3; ++a) {
      const float c = points[i][a];
      // The voxels within the truncation, without a division and a libm call per axis.
      const int low = CeilToInt((c - m.truncation_mm) * m.inverse_voxel);
      const int high = FloorToInt((c + m.truncation_mm) * m.inverse_voxel);
      b0[a] = (std::max(low, m.roi_lo[a]) >> 3) - m.base[a];
      b1[a] = (std::min(high, m.roi_hi[a]) >> 3) - m.base[a];
    }
    // Neighbouring pixels mostly mark the same blocks: skip a repeat of the last box.
    if (std::equal(b0, b0 + 3, last_b0) && std::equal(b1, b1 + 3, last_b1)) continue;
    std::copy(b0, b0 + 3, last_b0);
    std::copy(b1, b1 + 3, last_b1);
    MarkBox(m, b0, b1);
  }
}

#if defined(__x86_64__)

__attribute__((target("avx2"))) void MarkBlocksAvx2(const BlockMarker& m, const float* range_mm,
                                                    const std::array<float, 3>* points,
                                                    std::size_t begin, std::size_t end) {
  // Lane k is pixel i + k: its box as six index vectors (MarkBlocks' operations), compared with
  // the box of lane k - 1; only the lanes with a new box reach the scalar marking. Unusable
  // lanes get an empty box, so the lane after one always marks: the flags are MarkBlocks'.
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256i previous_lane = _mm256_setr_epi32(7, 0, 1, 2, 3, 4, 5, 6);
  const __m256i xyz = _mm256_mullo_epi32(lane, _mm256_set1_epi32(3));
  const __m256 truncation = _mm256_set1_ps(m.truncation_mm);
  const __m256 inverse_voxel = _mm256_set1_ps(m.inverse_voxel);
  __m256i last[6];  // the previous lane's box: b0 x y z, b1 x y z
  for (int a = 0; a < 3; ++a) last[a] = _mm256_set1_epi32(1), last[3 + a] = _mm256_setzero_si256();
  for (std::size_t i = begin; i < end; i += 8) {
    const __m256i in_span = _mm256_cmpgt_epi32(
        _mm256_set1_epi32(static_cast<int>(std::min<std::size_t>(end - i, 8))), lane);
    const __m256 range = _mm256_maskload_ps(range_mm + i, in_span);
    const __m256 usable = _mm256_and_ps(_mm256_castsi256_ps(in_span),
                                        _mm256_cmp_ps(range, _mm256_setzero_ps(), _CMP_GT_OQ));
    const int usable_bits = _mm256_movemask_ps(usable);
    if (usable_bits == 0) {
      for (int a = 0; a < 3; ++a)
        last[a] = _mm256_set1_epi32(1), last[3 + a] = _mm256_setzero_si256();
      continue;
    }
    const float* base = points[i].data();
    __m256i box[6];
    __m256i same = _mm256_set1_epi32(-1);
    for (int a = 0; a < 3; ++a) {
      const __m256 c = _mm256_mask_i32gather_ps(_mm256_setzero_ps(), base + a, xyz, usable, 4);
      const __m256 lo = _mm256_mul_ps(_mm256_sub_ps(c, truncation), inverse_voxel);
      const __m256 hi = _mm256_mul_ps(_mm256_add_ps(c, truncation), inverse_voxel);
      // CeilToInt / FloorToInt: truncate, then step by one where that went the wrong way.
      const __m256i lo_i = _mm256_cvttps_epi32(lo), hi_i = _mm256_cvttps_epi32(hi);
      const __m256i low = _mm256_sub_epi32(
          lo_i, _mm256_castps_si256(_mm256_cmp_ps(_mm256_cvtepi32_ps(lo_i), lo, _CMP_LT_OQ)));
      const __m256i high = _mm256_add_epi32(
          hi_i, _mm256_castps_si256(_mm256_cmp_ps(_mm256_cvtepi32_ps(hi_i), hi, _CMP_GT_OQ)));
      const __m256i base_key = _mm256_set1_epi32(m.base[a]);
      box[a] = _mm256_sub_epi32(
          _mm256_srai_epi32(_mm256_max_epi32(low, _mm256_set1_epi32(m.roi_lo[a])), 3), base_key);
      box[3 + a] = _mm256_sub_epi32(
          _mm256_srai_epi32(_mm256_min_epi32(high, _mm256_set1_epi32(m.roi_hi[a])), 3), base_key);
    }
    for (int k = 0; k < 6; ++k) {
      // Unusable lanes: the empty box b0 = 1, b1 = 0.
      box[k] =
          _mm256_blendv_epi8(_mm256_set1_epi32(k < 3 ? 1 : 0), box[k], _mm256_castps_si256(usable));
      // The previous lane's value: lane 0 takes lane 7 of the last group.
      const __m256i previous =
          _mm256_blend_epi32(_mm256_permutevar8x32_epi32(box[k], previous_lane),
                             _mm256_permutevar8x32_epi32(last[k], previous_lane), 0x01);
      same = _mm256_and_si256(same, _mm256_cmpeq_epi32(box[k], previous));
      last[k] = box[k];
    }
    int fresh = usable_bits & ~_mm256_movemask_ps(_mm256_castsi256_ps(same));
    if (fresh == 0) continue;
    alignas(32) int values[6][8];
    for (int k = 0; k < 6; ++k) _mm256_store_si256(reinterpret_cast<__m256i*>(values[k]), box[k]);
    for (; fresh != 0; fresh &= fresh - 1) {
      const int k = __builtin_ctz(static_cast<unsigned>(fresh));
      const int b0[3] = {values[0][k], values[1][k], values[2][k]};
      const int b1[3] = {values[3][k], values[4][k], values[5][k]};
      MarkBox(m, b0, b1);
    }
  }
}

#else  // not x86-64: the scalar loop only

void MarkBlocksAvx2(const BlockMarker&, const float*, const std::array<float, 3>*, std::size_t,
                    std::size_t) {
  throw std::logic_error("MarkBlocksAvx2: not an x86-64 build");
}

#endif

}  // namespace tofnav
