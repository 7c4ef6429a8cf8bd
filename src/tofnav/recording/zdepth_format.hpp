// SPDX-License-Identifier: BSD-3-Clause
// Zdepth bitstream constants and per-pixel rules shared by the encoder and decoder (internal).
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>

namespace tofnav {

inline constexpr std::uint8_t kZdepthMagic = 0xCA;
inline constexpr std::uint8_t kZdepthKeyFrameFlag = 1;
inline constexpr std::size_t kZdepthHeaderBytes = 40;
inline constexpr int kZdepthBlockPx = 8;
inline constexpr int kZdepthMaxSidePx = 4096;      // sanity bound on width and height (AHAT: 512)
inline constexpr int kZdepthFirstInvalidQ = 2040;  // q >= 2040 dequantises to 0 (docs/ahat.md 4.5)
inline constexpr unsigned kZdepthZigZagLimit = 4096;  // Pack12 holds 12 bits

/// Predictor ids of the Blocks section (docs/ahat.md 4.4); 6 (PrevFrame) is invalid in key frames.
enum ZdepthPredictor : int { kLarger, kUp, kLeft, kUpTrend, kLeftTrend, kAverage, kPrevFrame };

/// Azure Kinect quantisation (docs/ahat.md 4.5); d <= 200 mm is "no data".
constexpr int ZdepthQuantise(int range_mm) {
  int q = 0;
  if (range_mm <= 200)
    q = 0;
  else if (range_mm < 750)
    q = range_mm - 200;
  else if (range_mm < 1500)
    q = 550 + (range_mm - 750) / 2;
  else if (range_mm < 3000)
    q = 925 + (range_mm - 1500) / 4;
  else if (range_mm < 6000)
    q = 1300 + (range_mm - 3000) / 8;
  else if (range_mm < 12000)
    q = 1675 + (range_mm - 6000) / 16;
  // 11840..11999 mm quantise to 2040..2049, which decode as invalid anyway: emitting 0 instead
  // decodes identically and keeps every residual within 12 bits.
  return q < kZdepthFirstInvalidQ ? q : 0;
}

constexpr std::uint16_t ZdepthDequantise(int q) {
  int range_mm = 0;
  if (q <= 0 || q >= kZdepthFirstInvalidQ)
    range_mm = 0;
  else if (q < 550)
    range_mm = q + 200;
  else if (q < 925)
    range_mm = 750 + 2 * (q - 550);
  else if (q < 1300)
    range_mm = 1500 + 4 * (q - 925);
  else if (q < 1675)
    range_mm = 3000 + 8 * (q - 1300);
  else
    range_mm = 6000 + 16 * (q - 1675);
  return static_cast<std::uint16_t>(range_mm);
}

inline unsigned ZdepthZigZag(int delta) {
  return (static_cast<unsigned>(delta) << 1) ^ static_cast<unsigned>(delta >> 31);
}
inline std::int16_t ZdepthUnZigZag(unsigned z) {  // z < 4096, so the result fits
  return static_cast<std::int16_t>(static_cast<int>(z >> 1) ^ -static_cast<int>(z & 1u));
}

/// Prediction from the left/up neighbours l, u and l2, u2 two away; 0 means "no data".
template <int kId>
inline int ZdepthPredict(int l, int u, int l2, int u2) {
  const int larger = std::max(l, u);
  if constexpr (kId == kUp) return u != 0 ? u : l;
  if constexpr (kId == kLeft) return l != 0 ? l : u;
  if constexpr (kId == kUpTrend) return (u != 0 && u2 != 0) ? 2 * u - u2 : larger;
  if constexpr (kId == kLeftTrend) return (l != 0 && l2 != 0) ? 2 * l - l2 : larger;
  if constexpr (kId == kAverage) return (l != 0 && u != 0) ? (l + u) / 2 : larger;
  return larger;  // kLarger, and unknown ids as the reference decoder does
}

/// Interior blocks: one predictor byte per block, (W/8 - 1) * (H/8 - 1).
inline std::size_t ZdepthInteriorBlockCount(int width, int height) {
  return static_cast<std::size_t>(width / kZdepthBlockPx - 1) *
         static_cast<std::size_t>(height / kZdepthBlockPx - 1);
}

}  // namespace tofnav
