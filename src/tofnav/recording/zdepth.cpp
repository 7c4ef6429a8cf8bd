// SPDX-License-Identifier: BSD-3-Clause
// Zdepth key frames (docs/ahat.md 4): zero map, 8x8 block predictors, Pack12, four zstd frames.
#include "tofnav/recording/zdepth.hpp"

#include <zstd.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>

#include "tofnav/io/binary.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/recording/zdepth_format.hpp"

namespace tofnav {
namespace {

constexpr int kQuantisedLimit = 4096;  // a decoded pixel must be 1..4095 (encoders give <= 2049)
constexpr std::size_t kStreamPadding = kZdepthBlockPx * kZdepthBlockPx;  // one check per block

// Zero-map byte -> its eight 0/1 placeholders (LSB first) and their count: one 16-byte copy per
// byte (std::popcount alone is a library call without -mpopcnt).
struct ZeroMapByte {
  std::uint16_t placeholders[8];
  std::size_t non_zero;
};
constexpr std::array<ZeroMapByte, 256> kZeroMapBytes = [] {
  std::array<ZeroMapByte, 256> table{};
  for (unsigned b = 0; b < 256; ++b) {
    for (unsigned j = 0; j < 8; ++j) table[b].placeholders[j] = (b >> j) & 1u;
    table[b].non_zero = static_cast<std::size_t>(std::popcount(b));
  }
  return table;
}();

constexpr std::array<std::uint16_t, kQuantisedLimit> kDequantised = [] {
  std::array<std::uint16_t, kQuantisedLimit> table{};
  for (int q = 0; q < kQuantisedLimit; ++q) {
    table[static_cast<std::size_t>(q)] = ZdepthDequantise(q);
  }
  return table;
}();

struct Section {
  const char* name;
  std::uint32_t raw_bytes = 0;
  std::uint32_t packed_bytes = 0;
  std::uint64_t field_offset = 0;  // of the uncompressed-size field in the header
  std::uint64_t offset = 0;        // of the zstd frame in `bytes`
};

struct Context {
  const std::filesystem::path& source;
  std::uint64_t base_offset;
  [[noreturn]] void Fail(std::uint64_t offset, const std::string& expected) const {
    throw IoError(source, base_offset + offset, "expected " + expected);
  }
};

struct DCtxDeleter {
  void operator()(ZSTD_DCtx* dctx) const { ZSTD_freeDCtx(dctx); }
};

/// Decompresses one section into exactly `section.raw_bytes` bytes.
std::vector<std::uint8_t> Inflate(const Context& ctx, ZSTD_DCtx* dctx,
                                  std::span<const std::uint8_t> bytes, const Section& section) {
  std::vector<std::uint8_t> raw(section.raw_bytes);
  if (section.packed_bytes == 0) {  // an empty section may be stored without a frame
    if (section.raw_bytes != 0) {
      ctx.Fail(section.offset, std::string("a zstd frame for ") + section.name);
    }
    return raw;
  }
  const auto src = bytes.subspan(static_cast<std::size_t>(section.offset), section.packed_bytes);
  const unsigned long long declared = ZSTD_getFrameContentSize(src.data(), src.size());
  if (declared == ZSTD_CONTENTSIZE_ERROR) {
    ctx.Fail(section.offset,
             std::string("a zstd frame header for the ") + section.name + " section");
  }
  if (declared != ZSTD_CONTENTSIZE_UNKNOWN && declared != section.raw_bytes) {
    ctx.Fail(section.offset, std::string("the ") + section.name + " zstd frame to hold " +
                                 std::to_string(section.raw_bytes) + " bytes, it declares " +
                                 std::to_string(declared));
  }
  std::uint8_t empty = 0;  // never hand zstd a null destination
  const std::size_t got = ZSTD_decompressDCtx(dctx, raw.empty() ? &empty : raw.data(), raw.size(),
                                              src.data(), src.size());
  if (ZSTD_isError(got) || got != raw.size()) {
    ctx.Fail(section.offset, std::string("the ") + section.name + " zstd frame to decompress to " +
                                 std::to_string(raw.size()) + " bytes" +
                                 (ZSTD_isError(got) ? std::string(": ") + ZSTD_getErrorName(got)
                                                    : ", got " + std::to_string(got)));
  }
  return raw;
}

/// Zero map (docs/ahat.md 4.3): bit i = nz(i) XOR nz(i - 1), LSB first. Writes 0/1 placeholders and
/// returns how many pixels are non-zero.
std::size_t ExpandZeroMap(std::span<const std::uint8_t> zeroes, std::uint16_t* pixels) {
  unsigned state = 0;
  std::size_t non_zero = 0;
  for (std::size_t k = 0; k < zeroes.size(); ++k) {
    unsigned bits = zeroes[k];
    bits ^= bits << 1;  // prefix XOR: bit j becomes the XOR of bits 0..j
    bits ^= bits << 2;
    bits ^= bits << 4;
    bits = (bits ^ (0u - state)) & 0xFFu;
    state = bits >> 7;
    std::memcpy(pixels + 8 * k, kZeroMapBytes[bits].placeholders,
                sizeof(ZeroMapByte::placeholders));
    non_zero += kZeroMapBytes[bits].non_zero;
  }
  return non_zero;
}

/// Pack12 (docs/ahat.md 4.2) to residuals, followed by kStreamPadding zeros.
std::vector<std::int16_t> UnpackResiduals(std::span<const std::uint8_t> packed) {
  const std::size_t count = packed.size() / 3 * 2;
  std::vector<std::int16_t> residuals(count + kStreamPadding, 0);
  const std::uint8_t* high = packed.data();
  const std::uint8_t* low = high + count;
  std::int16_t* out = residuals.data();
  for (std::size_t j = 0; j < count / 2; ++j) {  // written to auto-vectorise
    const unsigned nibbles = low[j];
    out[2 * j] = ZdepthUnZigZag((unsigned{high[2 * j]} << 4) | (nibbles & 15u));
    out[2 * j + 1] = ZdepthUnZigZag((unsigned{high[2 * j + 1]} << 4) | (nibbles >> 4));
  }
  return residuals;
}

struct Cursor {
  const std::int16_t* edge;
  const std::int16_t* surface;
  unsigned bad = 0;  // non-zero once a pixel left 1..kQuantisedLimit-1
};

constexpr std::uint16_t kZeroRow[kZdepthBlockPx] = {};

/// One 8x8 block (docs/ahat.md 4.4). Edge blocks (kEdge) see 0 outside the block and use Larger;
/// interior blocks see the real, already decoded image. A pixel takes its residual from Edges when
/// L or U is 0, else from Surfaces. L and L2 stay in registers (no store-to-load round trip). The
/// store wraps to 16 bits so a corrupt stream cannot overflow later predictions; `bad` flags it.
template <int kId, bool kEdge>
void DecodeBlock(std::uint16_t* origin, int width, Cursor& cursor) {
  const std::int16_t* edge = cursor.edge;
  const std::int16_t* surface = cursor.surface;
  unsigned bad = 0;
  for (int y = 0; y < kZdepthBlockPx; ++y) {
    std::uint16_t* row = origin + static_cast<std::ptrdiff_t>(y) * width;
    const std::uint16_t* up = kEdge && y == 0 ? kZeroRow : row - width;
    const std::uint16_t* up2 = kEdge ? up : row - 2 * width;  // only trend predictors read it
    int l = kEdge ? 0 : row[-1];
    int l2 = kEdge ? 0 : row[-2];
    for (int x = 0; x < kZdepthBlockPx; ++x) {
      int q = row[x];
      if (q != 0) {
        const int u = up[x];
        const bool on_surface = l != 0 && u != 0;
        const int value = ZdepthPredict<kId>(l, u, l2, up2[x]) + (on_surface ? *surface : *edge);
        surface += on_surface ? 1 : 0;
        edge += on_surface ? 0 : 1;
        bad |= static_cast<unsigned>(value - 1) >= unsigned{kQuantisedLimit - 1} ? 1u : 0u;
        q = static_cast<std::uint16_t>(value);
        row[x] = static_cast<std::uint16_t>(q);
      }
      l2 = l;
      l = q;
    }
  }
  cursor.edge = edge;
  cursor.surface = surface;
  cursor.bad |= bad;
}

void DecodeInteriorBlock(int id, std::uint16_t* origin, int width, Cursor& cursor) {
  switch (id) {
    case kUp:
      return DecodeBlock<kUp, false>(origin, width, cursor);
    case kLeft:
      return DecodeBlock<kLeft, false>(origin, width, cursor);
    case kUpTrend:
      return DecodeBlock<kUpTrend, false>(origin, width, cursor);
    case kLeftTrend:
      return DecodeBlock<kLeftTrend, false>(origin, width, cursor);
    case kAverage:
      return DecodeBlock<kAverage, false>(origin, width, cursor);
    default:
      return DecodeBlock<kLarger, false>(origin, width, cursor);  // ids > 6 too
  }
}

struct FrameHeader {
  int width = 0, height = 0;
  Section zeroes{"Zeroes"}, blocks{"Blocks"}, edges{"Edges"}, surfaces{"Surfaces"};
};

/// The 40-byte header (docs/ahat.md 4.1) with every size checked against the image and `bytes`.
FrameHeader ReadHeader(const Context& ctx, std::span<const std::uint8_t> bytes) {
  ByteReader reader(bytes, ctx.source, ctx.base_offset);
  reader.Take(kZdepthHeaderBytes, "Zdepth header");
  reader = ByteReader(bytes, ctx.source, ctx.base_offset);
  if (reader.Le<std::uint8_t>("magic") != kZdepthMagic) ctx.Fail(0, "Zdepth magic 0xCA");
  if ((reader.Le<std::uint8_t>("flags") & kZdepthKeyFrameFlag) == 0) {
    ctx.Fail(1, "a key frame (flags bit 0)");
  }
  reader.Skip(2, "frame number");
  FrameHeader header;
  header.width = reader.Le<std::uint16_t>("width");
  header.height = reader.Le<std::uint16_t>("height");
  for (const auto& [side, offset] : {std::pair{header.width, 4u}, std::pair{header.height, 6u}}) {
    if (side == 0 || side % kZdepthBlockPx != 0 || side > kZdepthMaxSidePx) {
      ctx.Fail(offset, "width and height to be non-zero multiples of 8 up to 4096, found " +
                           std::to_string(side));
    }
  }
  std::uint64_t end = kZdepthHeaderBytes;
  for (Section* section : {&header.zeroes, &header.blocks, &header.edges, &header.surfaces}) {
    section->field_offset = reader.position();
    section->raw_bytes = reader.Le<std::uint32_t>("uncompressed size");
    section->packed_bytes = reader.Le<std::uint32_t>("compressed size");
    section->offset = end;
    end += section->packed_bytes;
  }
  if (end != bytes.size()) {
    ctx.Fail(bytes.size(), std::to_string(end) + " bytes (40 + compressed sections), found " +
                               std::to_string(bytes.size()));
  }
  const std::size_t zeroes_bytes =
      static_cast<std::size_t>(header.width) * static_cast<std::size_t>(header.height) / 8;
  if (header.zeroes.raw_bytes != zeroes_bytes) {
    ctx.Fail(header.zeroes.field_offset, "Zeroes size W*H/8 = " + std::to_string(zeroes_bytes));
  }
  const std::size_t block_count = ZdepthInteriorBlockCount(header.width, header.height);
  if (header.blocks.raw_bytes != block_count || block_count < 2) {
    ctx.Fail(header.blocks.field_offset,
             "Blocks size (W/8-1)*(H/8-1) = " + std::to_string(block_count) + " (at least 2)");
  }
  for (const Section* pack : {&header.edges, &header.surfaces}) {
    if (pack->raw_bytes % 3 != 0) ctx.Fail(pack->field_offset, "a Pack12 size divisible by 3");
  }
  return header;
}

/// Residual stream with kStreamPadding readable zeros after `end`.
struct Stream {
  std::vector<std::int16_t> values;
  const std::int16_t* end() const { return values.data() + (values.size() - kStreamPadding); }
};

/// Block walk (docs/ahat.md 4.4) over `image`, which holds the zero-map placeholders.
void WalkBlocks(const Context& ctx, const FrameHeader& header,
                const std::vector<std::uint8_t>& predictors, const Stream& edges,
                const Stream& surfaces, Image<std::uint16_t>& image) {
  const int width = header.width;
  const int blocks_x = width / kZdepthBlockPx;
  Cursor cursor{edges.values.data(), surfaces.values.data()};
  for (int iy = 0; iy < header.height / kZdepthBlockPx; ++iy) {
    for (int ix = 0; ix < blocks_x; ++ix) {
      std::uint16_t* origin = image.data() +
                              static_cast<std::ptrdiff_t>(iy) * kZdepthBlockPx * width +
                              static_cast<std::ptrdiff_t>(ix) * kZdepthBlockPx;
      if (ix == 0 || iy == 0) {
        DecodeBlock<kLarger, true>(origin, width, cursor);
      } else {
        const auto index = static_cast<std::size_t>((iy - 1) * (blocks_x - 1) + (ix - 1));
        DecodeInteriorBlock(predictors[index], origin, width, cursor);
      }
      if (cursor.edge > edges.end() || cursor.surface > surfaces.end() || cursor.bad != 0) {
        const std::string block = "block (" + std::to_string(ix) + ", " + std::to_string(iy) + ")";
        if (cursor.edge > edges.end()) {
          ctx.Fail(header.edges.offset, "more Edges values for " + block);
        }
        if (cursor.surface > surfaces.end()) {
          ctx.Fail(header.surfaces.offset, "more Surfaces values for " + block);
        }
        ctx.Fail(header.edges.offset, "residuals giving quantised values in 1..4095 in " + block);
      }
    }
  }
  // The encoder pads an odd count with one value; anything more is left over from corruption.
  for (const auto& [at, stream, section] :
       {std::tuple{cursor.edge, &edges, &header.edges},
        std::tuple{cursor.surface, &surfaces, &header.surfaces}}) {
    const auto used = static_cast<std::size_t>(at - stream->values.data());
    const auto stored = static_cast<std::size_t>(stream->end() - stream->values.data());
    if (stored != used + (used & 1u)) {
      ctx.Fail(section->offset, std::to_string(used + (used & 1u)) + " " + section->name +
                                    " values (one per pixel, padded to even), found " +
                                    std::to_string(stored));
    }
  }
}

}  // namespace

void ZdepthEncodeOptions::Check() const {
  Require(zstd_level >= ZSTD_minCLevel() && zstd_level <= ZSTD_maxCLevel(),
          "ZdepthEncodeOptions.zstd_level must lie in ZSTD_minCLevel()..ZSTD_maxCLevel()");
}

std::uint16_t ZdepthRoundTripMm(std::uint16_t range_mm) {
  return ZdepthDequantise(ZdepthQuantise(range_mm));
}

Image<std::uint16_t> DecodeZdepth(std::span<const std::uint8_t> bytes,
                                  const std::filesystem::path& source, std::uint64_t base_offset) {
  const Context ctx{source, base_offset};
  const FrameHeader header = ReadHeader(ctx, bytes);
  const std::unique_ptr<ZSTD_DCtx, DCtxDeleter> dctx(ZSTD_createDCtx());
  if (!dctx) throw std::bad_alloc();
  Image<std::uint16_t> image(header.width, header.height);
  const std::size_t non_zero =
      ExpandZeroMap(Inflate(ctx, dctx.get(), bytes, header.zeroes), image.data());
  // Bound the residual streams before inflating them: one value per non-zero pixel, plus at
  // most one padding value per stream.
  const std::size_t stored =
      (std::size_t{header.edges.raw_bytes} + header.surfaces.raw_bytes) / 3 * 2;
  if (stored > non_zero + 2) {
    ctx.Fail(header.edges.field_offset,
             "at most " + std::to_string(non_zero + 2) +
                 " Edges + Surfaces values for the non-zero pixels, found " +
                 std::to_string(stored));
  }
  const std::vector<std::uint8_t> predictors = Inflate(ctx, dctx.get(), bytes, header.blocks);
  if (const auto bad = std::find(predictors.begin(), predictors.end(), std::uint8_t{kPrevFrame});
      bad != predictors.end()) {
    ctx.Fail(header.blocks.offset,
             "no PrevFrame predictor (6) in a key frame, found one at block " +
                 std::to_string(bad - predictors.begin()));
  }
  const Stream edges{UnpackResiduals(Inflate(ctx, dctx.get(), bytes, header.edges))};
  const Stream surfaces{UnpackResiduals(Inflate(ctx, dctx.get(), bytes, header.surfaces))};
  WalkBlocks(ctx, header, predictors, edges, surfaces, image);
  for (std::uint16_t& pixel : image.pixels()) pixel = kDequantised[pixel];  // docs/ahat.md 4.5
  return image;
}

}  // namespace tofnav
