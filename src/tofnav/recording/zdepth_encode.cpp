// SPDX-License-Identifier: BSD-3-Clause
// Zdepth key-frame encoder (docs/ahat.md 4.6): the mirror of the decoder's block walk.
#include <zstd.h>

#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

#include "tofnav/core/require.hpp"
#include "tofnav/recording/zdepth.hpp"
#include "tofnav/recording/zdepth_format.hpp"

namespace tofnav {
namespace {

struct Streams {
  std::vector<std::uint16_t> edges;     // zig-zag residuals
  std::vector<std::uint16_t> surfaces;  // zig-zag residuals
};

struct Neighbours {
  int l = 0, u = 0, l2 = 0, u2 = 0;
};

/// Left/up neighbours as the decoder sees them: outside the block count as 0 in edge blocks.
Neighbours NeighboursOf(const std::uint16_t* q, int width, int x, int y, bool edge_block) {
  const std::uint16_t* p = q + static_cast<std::ptrdiff_t>(y) * width + x;
  if (edge_block) {
    return {x % kZdepthBlockPx > 0 ? p[-1] : 0, y % kZdepthBlockPx > 0 ? p[-width] : 0, 0, 0};
  }
  return {p[-1], p[-width], p[-2], p[-2 * width]};
}

int PredictById(int id, const Neighbours& n) {
  switch (id) {
    case kUp:
      return ZdepthPredict<kUp>(n.l, n.u, n.l2, n.u2);
    case kLeft:
      return ZdepthPredict<kLeft>(n.l, n.u, n.l2, n.u2);
    case kUpTrend:
      return ZdepthPredict<kUpTrend>(n.l, n.u, n.l2, n.u2);
    case kLeftTrend:
      return ZdepthPredict<kLeftTrend>(n.l, n.u, n.l2, n.u2);
    case kAverage:
      return ZdepthPredict<kAverage>(n.l, n.u, n.l2, n.u2);
    default:
      return ZdepthPredict<kLarger>(n.l, n.u, n.l2, n.u2);
  }
}

/// Sum of zig-zag residuals of block (bx, by) under predictor `id`; max() when one does not fit
/// in 12 bits (only the trend predictors can overshoot).
std::uint64_t BlockCost(const std::uint16_t* q, int width, int bx, int by, int id) {
  std::uint64_t cost = 0;
  for (int y = by; y < by + kZdepthBlockPx; ++y) {
    for (int x = bx; x < bx + kZdepthBlockPx; ++x) {
      const int value = q[static_cast<std::ptrdiff_t>(y) * width + x];
      if (value == 0) continue;
      const unsigned z = ZdepthZigZag(value - PredictById(id, NeighboursOf(q, width, x, y, false)));
      if (z >= kZdepthZigZagLimit) return std::numeric_limits<std::uint64_t>::max();
      cost += z;
    }
  }
  return cost;
}

void EncodeBlock(const std::uint16_t* q, int width, int bx, int by, bool edge_block, int id,
                 Streams& streams) {
  for (int y = by; y < by + kZdepthBlockPx; ++y) {
    for (int x = bx; x < bx + kZdepthBlockPx; ++x) {
      const int value = q[static_cast<std::ptrdiff_t>(y) * width + x];
      if (value == 0) continue;
      const Neighbours n = NeighboursOf(q, width, x, y, edge_block);
      const unsigned z = ZdepthZigZag(value - PredictById(id, n));
      Require(z < kZdepthZigZagLimit, "Zdepth residual does not fit in 12 bits");
      (n.l != 0 && n.u != 0 ? streams.surfaces : streams.edges)
          .push_back(static_cast<std::uint16_t>(z));
    }
  }
}

/// Pack12 (docs/ahat.md 4.2): high bytes of all values, then one byte of low nibbles per pair.
std::vector<std::uint8_t> Pack12(std::vector<std::uint16_t> values) {
  if (values.size() % 2 != 0) values.push_back(0);
  const std::size_t count = values.size();
  std::vector<std::uint8_t> packed(count + count / 2);
  for (std::size_t k = 0; k < count; ++k) packed[k] = static_cast<std::uint8_t>(values[k] >> 4);
  for (std::size_t k = 0; k < count; k += 2) {
    packed[count + k / 2] =
        static_cast<std::uint8_t>((values[k] & 15u) | ((values[k + 1] & 15u) << 4));
  }
  return packed;
}

struct CCtxDeleter {
  void operator()(ZSTD_CCtx* cctx) const { ZSTD_freeCCtx(cctx); }
};

std::vector<std::uint8_t> Compress(ZSTD_CCtx* cctx, const std::vector<std::uint8_t>& raw,
                                   int level) {
  std::vector<std::uint8_t> packed(ZSTD_compressBound(raw.size()));
  const std::uint8_t empty = 0;  // never hand zstd a null source
  const std::size_t size = ZSTD_compressCCtx(cctx, packed.data(), packed.size(),
                                             raw.empty() ? &empty : raw.data(), raw.size(), level);
  if (ZSTD_isError(size)) {
    throw std::runtime_error(std::string("zstd compression failed: ") + ZSTD_getErrorName(size));
  }
  packed.resize(size);
  return packed;
}

/// Zero map (docs/ahat.md 4.3): bit i (LSB first) = nz(q_i) XOR nz(q_{i-1}).
std::vector<std::uint8_t> ZeroMap(const std::vector<std::uint16_t>& q) {
  std::vector<std::uint8_t> zeroes(q.size() / 8, 0);
  bool previous = false;
  for (std::size_t i = 0; i < q.size(); ++i) {
    const bool current = q[i] != 0;
    if (current != previous) zeroes[i / 8] |= static_cast<std::uint8_t>(1u << (i % 8));
    previous = current;
  }
  return zeroes;
}

/// The predictor with the smallest zig-zag sum over interior block (bx, by); ties keep the lower
/// id.
int ChoosePredictor(const std::uint16_t* q, int width, int bx, int by) {
  int best_id = kLarger;
  std::uint64_t best = BlockCost(q, width, bx, by, kLarger);  // always fits in 12 bits
  for (int id = kLarger + 1; id < kPrevFrame; ++id) {
    const std::uint64_t cost = BlockCost(q, width, bx, by, id);
    if (cost < best) {
      best = cost;
      best_id = id;
    }
  }
  return best_id;
}

/// 40-byte header (docs/ahat.md 4.1, little-endian) and the four sections as zstd frames. Not via
/// ByteWriter: GCC 12 -O3 warns falsely (-Wstringop-overflow) on its 2-byte vector::insert.
std::vector<std::uint8_t> AssembleFrame(int width, int height,
                                        const std::vector<std::uint8_t> (&sections)[4], int level) {
  std::vector<std::uint8_t> frame(kZdepthHeaderBytes, 0);
  const auto put = [&frame](std::size_t at, std::size_t value, std::size_t bytes) {
    for (std::size_t k = 0; k < bytes; ++k) {
      frame[at + k] = static_cast<std::uint8_t>(value >> (8 * k));
    }
  };
  put(0, kZdepthMagic, 1);
  put(1, kZdepthKeyFrameFlag, 1);
  put(2, 0, 2);  // frame number, unused in key frames
  put(4, static_cast<std::size_t>(width), 2);
  put(6, static_cast<std::size_t>(height), 2);
  const std::unique_ptr<ZSTD_CCtx, CCtxDeleter> cctx(ZSTD_createCCtx());
  if (!cctx) throw std::bad_alloc();
  for (std::size_t s = 0; s < 4; ++s) {
    const std::vector<std::uint8_t> packed = Compress(cctx.get(), sections[s], level);
    put(8 + 8 * s, sections[s].size(), 4);
    put(12 + 8 * s, packed.size(), 4);
    frame.insert(frame.end(), packed.begin(), packed.end());
  }
  return frame;
}

}  // namespace

std::vector<std::uint8_t> EncodeZdepth(const Image<std::uint16_t>& range_mm,
                                       const ZdepthEncodeOptions& options) {
  options.Check();
  const int width = range_mm.width();
  const int height = range_mm.height();
  Require(width > 0 && height > 0 && width % kZdepthBlockPx == 0 && height % kZdepthBlockPx == 0 &&
              width <= kZdepthMaxSidePx && height <= kZdepthMaxSidePx,
          "Zdepth needs width and height to be non-zero multiples of 8 up to 4096");
  Require(ZdepthInteriorBlockCount(width, height) >= 2,
          "Zdepth needs at least two interior blocks ((W/8-1)*(H/8-1) >= 2)");

  std::vector<std::uint16_t> q(range_mm.size());
  for (std::size_t i = 0; i < q.size(); ++i) {
    q[i] = static_cast<std::uint16_t>(ZdepthQuantise(range_mm.pixels()[i]));
  }
  // Block walk in the decoder's order (docs/ahat.md 4.4), so the residual streams line up.
  const int blocks_x = width / kZdepthBlockPx;
  std::vector<std::uint8_t> predictors(ZdepthInteriorBlockCount(width, height), kLarger);
  Streams streams;
  for (int iy = 0; iy < height / kZdepthBlockPx; ++iy) {
    for (int ix = 0; ix < blocks_x; ++ix) {
      const int bx = ix * kZdepthBlockPx;
      const int by = iy * kZdepthBlockPx;
      const bool edge_block = ix == 0 || iy == 0;
      int id = kLarger;
      if (!edge_block && options.choose_predictors) {
        id = ChoosePredictor(q.data(), width, bx, by);
        predictors[static_cast<std::size_t>((iy - 1) * (blocks_x - 1) + (ix - 1))] =
            static_cast<std::uint8_t>(id);
      }
      EncodeBlock(q.data(), width, bx, by, edge_block, id, streams);
    }
  }
  const std::vector<std::uint8_t> sections[4] = {ZeroMap(q), std::move(predictors),
                                                 Pack12(std::move(streams.edges)),
                                                 Pack12(std::move(streams.surfaces))};
  return AssembleFrame(width, height, sections, options.zstd_level);
}

}  // namespace tofnav
