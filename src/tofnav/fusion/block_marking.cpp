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

/// Distance from the coordinate c to the voxels 8 key .. 8 key + 7 of a block along one axis,
/// all in voxels; 0 between them.
float SlabDistance(float c, int key) {
  const auto lo = static_cast<float>(8 * key), hi = static_cast<float>(8 * key + 7);
  return std::max(std::max(lo - c, 0.0f), c - hi);
}

/// Square of the truncation in voxels.
float SquaredTruncation(const BlockMarker& m) {
  const float t = m.truncation_mm * m.inverse_voxel;
  return t * t;
}

void SetFlag(const BlockMarker& m, int x, int y, int z) {
  const auto i = static_cast<std::size_t>(x + m.stride_y * y + m.stride_z * z);
  // Concurrent rows may mark the same block: a relaxed store of the same value.
  std::atomic_ref<std::uint8_t>(m.mask[i]).store(1, std::memory_order_relaxed);
}

/// Sets the flags of the blocks b0 .. b1 (inclusive, relative to the mask's base) whose voxels'
/// box comes within the truncation of the point cv (in voxels).
void MarkBall(const BlockMarker& m, const int b0[3], const int b1[3], const float cv[3]) {
  const float t2 = SquaredTruncation(m);
  for (int z = b0[2]; z <= b1[2]; ++z) {
    const float ez = SlabDistance(cv[2], z + m.base[2]);
    for (int y = b0[1]; y <= b1[1]; ++y) {
      const float ey = SlabDistance(cv[1], y + m.base[1]);
      for (int x = b0[0]; x <= b1[0]; ++x) {
        const float ex = SlabDistance(cv[0], x + m.base[0]);
        if ((ex * ex + ey * ey) + ez * ez <= t2) SetFlag(m, x, y, z);
      }
    }
  }
}

}  // namespace

void MarkBlocks(const BlockMarker& m, const float* range_mm, const std::array<float, 3>* points,
                std::size_t begin, std::size_t end) {
  // Blocks are 8 voxels: a voxel index's block is index >> 3 (floor division).
  for (std::size_t i = begin; i < end; ++i) {
    if (range_mm[i] <= 0.0f) continue;
    int b0[3], b1[3];
    float cv[3];
    for (std::size_t a = 0; a < 3; ++a) {
      const float c = points[i][a];
      // The box of voxels within the truncation, without a division and a libm call per axis.
      const int low = CeilToInt((c - m.truncation_mm) * m.inverse_voxel);
      const int high = FloorToInt((c + m.truncation_mm) * m.inverse_voxel);
      b0[a] = (std::max(low, m.roi_lo[a]) >> 3) - m.base[a];
      b1[a] = (std::min(high, m.roi_hi[a]) >> 3) - m.base[a];
      cv[a] = c * m.inverse_voxel;
    }
    MarkBall(m, b0, b1, cv);
  }
}

#if defined(__x86_64__)

__attribute__((target("avx2"))) void MarkBlocksAvx2(const BlockMarker& m, const float* range_mm,
                                                    const std::array<float, 3>* points,
                                                    std::size_t begin, std::size_t end) {
  // Lane k is pixel i + k: MarkBlocks' box and, when it spans at most two blocks per axis (the
  // usual truncation of a few voxels), which of its blocks pass the distance test as bits
  // dx | dy << 1 | dz << 2 of the block b0 + (dx, dy, dz), with MarkBlocks' operations. Wider
  // boxes take MarkBall.
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256i xyz = _mm256_mullo_epi32(lane, _mm256_set1_epi32(3));
  const __m256i one = _mm256_set1_epi32(1);
  const __m256 truncation = _mm256_set1_ps(m.truncation_mm);
  const __m256 inverse_voxel = _mm256_set1_ps(m.inverse_voxel);
  const __m256 t2 = _mm256_set1_ps(SquaredTruncation(m));
  // The flags set so far for the blocks b0 + (0 or 1 per axis) of the last run of lanes with
  // one b0, as corner bits: lanes of a run mostly add nothing. Locals, not reads through `m`,
  // which the flag stores could alias.
  std::uint8_t* const mask = m.mask;
  const std::int64_t stride_y = m.stride_y, stride_z = m.stride_z;
  std::int64_t corner_offset[8];
  for (int corner = 0; corner < 8; ++corner)
    corner_offset[corner] = (corner & 1) + stride_y * (corner >> 1 & 1) + stride_z * (corner >> 2);
  int run_b0[3] = {-1, -1, -1}, run_bits = 0;
  std::uint8_t* run_flag = mask;
  for (std::size_t i = begin; i < end; i += 8) {
    const __m256i in_span = _mm256_cmpgt_epi32(
        _mm256_set1_epi32(static_cast<int>(std::min<std::size_t>(end - i, 8))), lane);
    const __m256 range = _mm256_maskload_ps(range_mm + i, in_span);
    const __m256 usable = _mm256_and_ps(_mm256_castsi256_ps(in_span),
                                        _mm256_cmp_ps(range, _mm256_setzero_ps(), _CMP_GT_OQ));
    const int usable_bits = _mm256_movemask_ps(usable);
    if (usable_bits == 0) continue;
    const float* base = points[i].data();
    __m256i key[4], b1[3], wide = _mm256_setzero_si256();
    __m256 cv[3], near[3][2];  // per axis: distance^2 to the slabs of blocks b0 and b0 + 1
    __m256i spans[3];          // b1 - b0
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
      key[a] = _mm256_sub_epi32(
          _mm256_srai_epi32(_mm256_max_epi32(low, _mm256_set1_epi32(m.roi_lo[a])), 3), base_key);
      b1[a] = _mm256_sub_epi32(
          _mm256_srai_epi32(_mm256_min_epi32(high, _mm256_set1_epi32(m.roi_hi[a])), 3), base_key);
      spans[a] = _mm256_sub_epi32(b1[a], key[a]);
      wide = _mm256_or_si256(wide, _mm256_cmpgt_epi32(spans[a], one));
      cv[a] = _mm256_mul_ps(c, inverse_voxel);
      for (int d = 0; d < 2; ++d) {  // SlabDistance to block b0 + d, squared
        const __m256i first = _mm256_slli_epi32(
            _mm256_add_epi32(_mm256_add_epi32(key[a], base_key), _mm256_set1_epi32(d)), 3);
        const __m256 slab_lo = _mm256_cvtepi32_ps(first);
        const __m256 slab_hi = _mm256_cvtepi32_ps(_mm256_add_epi32(first, _mm256_set1_epi32(7)));
        const __m256 e =
            _mm256_max_ps(_mm256_max_ps(_mm256_sub_ps(slab_lo, cv[a]), _mm256_setzero_ps()),
                          _mm256_sub_ps(cv[a], slab_hi));
        near[a][d] = _mm256_mul_ps(e, e);
      }
    }
    __m256i bits = _mm256_setzero_si256();
    for (int corner = 0; corner < 8; ++corner) {
      const int dx = corner & 1, dy = (corner >> 1) & 1, dz = corner >> 2;
      const __m256 d2 = _mm256_add_ps(_mm256_add_ps(near[0][dx], near[1][dy]), near[2][dz]);
      __m256i pass = _mm256_castps_si256(_mm256_cmp_ps(d2, t2, _CMP_LE_OQ));
      // Block b0 + d exists in the box only where b1 - b0 >= d.
      pass = _mm256_andnot_si256(_mm256_cmpgt_epi32(_mm256_set1_epi32(dx), spans[0]), pass);
      pass = _mm256_andnot_si256(_mm256_cmpgt_epi32(_mm256_set1_epi32(dy), spans[1]), pass);
      pass = _mm256_andnot_si256(_mm256_cmpgt_epi32(_mm256_set1_epi32(dz), spans[2]), pass);
      bits = _mm256_or_si256(bits, _mm256_and_si256(pass, _mm256_set1_epi32(1 << corner)));
    }
    alignas(32) int values[8][8];  // b0 x y z, bits, b1 x y z
    alignas(32) float points_vox[3][8];
    for (int a = 0; a < 3; ++a) _mm256_store_si256(reinterpret_cast<__m256i*>(values[a]), key[a]);
    _mm256_store_si256(reinterpret_cast<__m256i*>(values[3]), bits);
    const int wide_bits = _mm256_movemask_ps(_mm256_castsi256_ps(wide)) & usable_bits;
    if (wide_bits != 0) {
      for (int a = 0; a < 3; ++a) {
        _mm256_store_si256(reinterpret_cast<__m256i*>(values[4 + a]), b1[a]);
        _mm256_store_ps(points_vox[a], cv[a]);
      }
    }
    for (int lanes = usable_bits; lanes != 0; lanes &= lanes - 1) {
      const int k = __builtin_ctz(static_cast<unsigned>(lanes));
      const int b0[3] = {values[0][k], values[1][k], values[2][k]};
      if ((wide_bits >> k & 1) != 0) {
        const int last_block[3] = {values[4][k], values[5][k], values[6][k]};
        const float point[3] = {points_vox[0][k], points_vox[1][k], points_vox[2][k]};
        MarkBall(m, b0, last_block, point);
        continue;
      }
      if (b0[0] != run_b0[0] || b0[1] != run_b0[1] || b0[2] != run_b0[2]) {
        std::copy(b0, b0 + 3, run_b0);
        run_bits = 0;
        run_flag = mask + (b0[0] + stride_y * b0[1] + stride_z * b0[2]);
      }
      for (int fresh = values[3][k] & ~run_bits; fresh != 0; fresh &= fresh - 1) {
        // Concurrent rows may mark the same block: a relaxed store of the same value.
        std::atomic_ref<std::uint8_t>(
            run_flag[corner_offset[__builtin_ctz(static_cast<unsigned>(fresh))]])
            .store(1, std::memory_order_relaxed);
      }
      run_bits |= values[3][k];
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
