// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/recording/zdepth.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <zstd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <random>
#include <string>

#include "tofnav/io/io_error.hpp"

namespace tofnav {
namespace {

// Header offsets (docs/ahat.md 4.1): uncompressed/compressed size of section s at 8 + 8 s (+4).
constexpr std::size_t kHeaderBytes = 40;
std::size_t RawSizeAt(int section) { return 8 + 8 * static_cast<std::size_t>(section); }
std::size_t PackedSizeAt(int section) { return RawSizeAt(section) + 4; }
enum SectionId { kZeroes, kBlocks, kEdges, kSurfaces };

void PutU32(std::vector<std::uint8_t>& bytes, std::size_t at, std::uint32_t value) {
  for (std::size_t k = 0; k < 4; ++k) bytes[at + k] = static_cast<std::uint8_t>(value >> (8 * k));
}
std::uint32_t GetU32(const std::vector<std::uint8_t>& bytes, std::size_t at) {
  return bytes[at] | bytes[at + 1] << 8 | bytes[at + 2] << 16 | std::uint32_t{bytes[at + 3]} << 24;
}

/// A frame as its four uncompressed sections, built here from the spec, not by the encoder.
struct RawFrame {
  int width = 0, height = 0;
  std::vector<std::uint8_t> sections[4];
};

/// One zstd frame; `content_size` false leaves the decompressed size out of the frame header.
std::vector<std::uint8_t> Zstd(const std::vector<std::uint8_t>& raw, bool content_size) {
  std::vector<std::uint8_t> out(ZSTD_compressBound(raw.size()));
  ZSTD_CCtx* cctx = ZSTD_createCCtx();
  ZSTD_CCtx_setParameter(cctx, ZSTD_c_contentSizeFlag, content_size ? 1 : 0);
  const std::size_t size = ZSTD_compress2(cctx, out.data(), out.size(), raw.data(), raw.size());
  ZSTD_freeCCtx(cctx);
  EXPECT_FALSE(ZSTD_isError(size));
  out.resize(size);
  return out;
}

std::vector<std::uint8_t> Assemble(const RawFrame& frame, bool content_size = true) {
  std::vector<std::uint8_t> bytes = {0xCA, 1, 7, 0};  // magic, key frame, frame number 7
  for (int side : {frame.width, frame.height}) {
    bytes.push_back(static_cast<std::uint8_t>(side & 0xFF));
    bytes.push_back(static_cast<std::uint8_t>(side >> 8));
  }
  bytes.resize(kHeaderBytes);
  for (int s = 0; s < 4; ++s) {
    const auto packed = Zstd(frame.sections[s], content_size);
    PutU32(bytes, RawSizeAt(s), static_cast<std::uint32_t>(frame.sections[s].size()));
    PutU32(bytes, PackedSizeAt(s), static_cast<std::uint32_t>(packed.size()));
    bytes.insert(bytes.end(), packed.begin(), packed.end());
  }
  return bytes;
}

/// Splits a valid frame back into its sections (to corrupt them semantically).
RawFrame Disassemble(const std::vector<std::uint8_t>& bytes) {
  RawFrame frame{bytes[4] | (bytes[5] << 8), bytes[6] | (bytes[7] << 8), {}};
  std::size_t at = kHeaderBytes;
  for (int s = 0; s < 4; ++s) {
    frame.sections[s].resize(GetU32(bytes, RawSizeAt(s)));
    const std::size_t packed = GetU32(bytes, PackedSizeAt(s));
    const std::size_t got = ZSTD_decompress(frame.sections[s].data(), frame.sections[s].size(),
                                            bytes.data() + at, packed);
    EXPECT_EQ(got, frame.sections[s].size());
    at += packed;
  }
  return frame;
}

/// Zero map from the spec: bit i (LSB first) = nz(i) XOR nz(i - 1).
std::vector<std::uint8_t> ZeroMap(const std::vector<int>& q) {
  std::vector<std::uint8_t> bits(q.size() / 8, 0);
  for (std::size_t i = 0; i < q.size(); ++i) {
    const bool before = i > 0 && q[i - 1] != 0;
    if ((q[i] != 0) != before) bits[i / 8] |= static_cast<std::uint8_t>(1 << (i % 8));
  }
  return bits;
}

/// Pack12 from the spec: high bytes, then (even & 15) | (odd & 15) << 4.
std::vector<std::uint8_t> Pack12(std::vector<unsigned> z) {
  if (z.size() % 2 != 0) z.push_back(0);
  std::vector<std::uint8_t> out;
  for (unsigned v : z) out.push_back(static_cast<std::uint8_t>(v >> 4));
  for (std::size_t k = 0; k < z.size(); k += 2) {
    out.push_back(static_cast<std::uint8_t>((z[k] & 15) | ((z[k + 1] & 15) << 4)));
  }
  return out;
}

// 24x16 = 3x2 blocks; interior blocks (1,1) with Average (5) and (2,1) with UpTrend (3).
// Quantised pixels and, in walk order, the residuals worked out by hand from docs/ahat.md 4.4.
struct HandPixel {
  int x, y, q;
};
constexpr HandPixel kHandPixels[] = {
    {1, 0, 600},  {7, 0, 50},   {1, 1, 605},  // block (0,0): pred max(L, U) inside the block
    {8, 0, 300},  {8, 7, 390},                // block (1,0): (7,0) is outside the block -> L = 0
    {16, 0, 200}, {17, 0, 190},               // block (2,0): 190 - 200 = -10 -> z 19
    {7, 8, 395},                              // block (0,1): (7,7) is outside the block -> U = 0
    {8, 8, 400},  {9, 8, 402},  {8, 9, 404},  {9, 9, 410},  // block (1,1)
    {16, 8, 500}, {17, 8, 501}, {16, 9, 510}, {17, 9, 511}, {16, 10, 520}, {17, 10, 519}};
const std::vector<unsigned> kHandEdges = {1200, 100, 10, 600,  780, 400, 19,
                                          790,  4,   8,  1000, 2,   20,  0};
// (8,8): (395+390)/2 = 392 -> 8 -> 16; (9,9): (404+402)/2 = 403 -> 7 -> 14;
// (17,9): U2 = 0 -> max(510, 501) -> 1 -> 2; (17,10): 2*511 - 501 = 521 -> -2 -> 3.
const std::vector<unsigned> kHandSurfaces = {16, 14, 2, 3};

RawFrame HandFrame(std::vector<std::uint8_t> predictors = {5, 3}) {
  std::vector<int> q(24 * 16, 0);
  for (const HandPixel& p : kHandPixels) q[static_cast<std::size_t>(p.y * 24 + p.x)] = p.q;
  return {24, 16, {ZeroMap(q), std::move(predictors), Pack12(kHandEdges), Pack12(kHandSurfaces)}};
}

/// Smooth AHAT-like content: a tilted wall 850..1055 mm, a head-like dome 300..550 mm, noise,
/// random rectangular holes and 2 % single-pixel drop-outs.
Image<std::uint16_t> HeadLikeImage(int width, int height, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> noise_mm(0.0, 1.5);
  const double cx = width * (0.3 + 0.4 * unit(rng)), cy = height * (0.3 + 0.4 * unit(rng));
  const double radius = 0.35 * std::min(width, height);
  const double tilt = 0.5 * unit(rng);  // mm per px
  Image<std::uint16_t> image(width, height);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const double r2 = (std::pow(u - cx, 2) + std::pow(v - cy, 2)) / (radius * radius);
      double range_mm = 950.0 + tilt * (u - width / 2);
      if (r2 < 1.0) range_mm = 550.0 - 250.0 * std::sqrt(1.0 - r2);
      range_mm = std::clamp(range_mm + noise_mm(rng), 200.0, 1055.0);
      image(u, v) = unit(rng) < 0.02 ? 0 : static_cast<std::uint16_t>(range_mm);
    }
  }
  for (int hole = 0; hole < 6; ++hole) {
    const int u0 = static_cast<int>(unit(rng) * width), v0 = static_cast<int>(unit(rng) * height);
    const int u1 = std::min(width, u0 + 1 + static_cast<int>(unit(rng) * width / 4));
    const int v1 = std::min(height, v0 + 1 + static_cast<int>(unit(rng) * height / 4));
    for (int v = v0; v < v1; ++v) std::fill_n(&image(u0, v), u1 - u0, std::uint16_t{0});
  }
  return image;
}

Image<std::uint16_t> RandomImage(int width, int height, unsigned seed) {  // 0..4089 mm
  std::mt19937 rng(seed);
  Image<std::uint16_t> image(width, height);
  for (auto& pixel : image.pixels()) pixel = static_cast<std::uint16_t>(rng() % 4090);
  return image;
}

::testing::AssertionResult DecodesToRoundTrip(const Image<std::uint16_t>& range_mm,
                                              const ZdepthEncodeOptions& options) {
  Image<std::uint16_t> expected = range_mm;
  for (auto& pixel : expected.pixels()) pixel = ZdepthRoundTripMm(pixel);
  const Image<std::uint16_t> decoded = DecodeZdepth(EncodeZdepth(range_mm, options));
  if (decoded == expected) return ::testing::AssertionSuccess();
  if (decoded.size() != expected.size()) return ::testing::AssertionFailure() << "size differs";
  const auto [got, want] =
      std::mismatch(decoded.pixels().begin(), decoded.pixels().end(), expected.pixels().begin());
  return ::testing::AssertionFailure()
         << "pixel " << got - decoded.pixels().begin() << ": " << *got << " mm, expected " << *want;
}

/// Decodes as if the frame started at byte 1000 of "frame.zdepth"; expects an IoError naming the
/// file, an offset inside the frame (`offset` relative to its start, when given) and `what`.
void ExpectIoError(const std::vector<std::uint8_t>& bytes, const std::string& what = "expected",
                   std::optional<std::uint64_t> offset = std::nullopt) {
  constexpr std::uint64_t kBaseOffset = 1000;
  try {
    DecodeZdepth(bytes, "frame.zdepth", kBaseOffset);
    ADD_FAILURE() << "decoded a corrupt frame";
  } catch (const IoError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("frame.zdepth"));
    EXPECT_THAT(e.what(), ::testing::HasSubstr(what));
    ASSERT_TRUE(e.offset().has_value());
    EXPECT_THAT(*e.offset(), ::testing::AllOf(::testing::Ge(kBaseOffset),
                                              ::testing::Le(kBaseOffset + bytes.size())));
    EXPECT_EQ(*e.offset(), kBaseOffset + offset.value_or(*e.offset() - kBaseOffset));
  }
}

TEST(ZdepthRoundTripMm, FollowsTheAzureKinectTable) {
  const std::pair<int, int> cases[] = {
      {0, 0},       {200, 0},       {201, 201},   {749, 749},   {750, 750},   {751, 750},
      {1499, 1498}, {1500, 1500},   {1503, 1500}, {2999, 2996}, {3007, 3000}, {5999, 5992},
      {6015, 6000}, {11839, 11824}, {11840, 0},   {11999, 0},   {12000, 0},   {65535, 0}};
  for (const auto& [range_mm, expected_mm] : cases) {
    EXPECT_EQ(ZdepthRoundTripMm(static_cast<std::uint16_t>(range_mm)), expected_mm) << range_mm;
  }
}

TEST(Zdepth, ExactBelow750AndTwoMillimetreFloorAbove) {
  Image<std::uint16_t> range_mm(64, 48);
  for (std::size_t i = 0; i < range_mm.size(); ++i) {
    range_mm.pixels()[i] = static_cast<std::uint16_t>(201 + i % 1299);  // 201..1499 mm
  }
  const Image<std::uint16_t> decoded = DecodeZdepth(EncodeZdepth(range_mm));
  for (std::size_t i = 0; i < range_mm.size(); ++i) {
    const int d = range_mm.pixels()[i];
    EXPECT_EQ(decoded.pixels()[i], d < 750 ? d : d - (d - 750) % 2) << d;
  }
}

TEST(Zdepth, HandBuiltFrameDecodesToSpecPixels) {
  const Image<std::uint16_t> decoded = DecodeZdepth(Assemble(HandFrame()));
  Image<std::uint16_t> expected(24, 16);
  for (const HandPixel& p : kHandPixels) {
    expected(p.x, p.y) = static_cast<std::uint16_t>(p.q < 550 ? p.q + 200 : 750 + 2 * (p.q - 550));
  }
  EXPECT_EQ(decoded, expected);
}

TEST(Zdepth, AcceptsZstdFramesWithoutContentSize) {
  const auto bytes = Assemble(HandFrame(), false);
  EXPECT_EQ(ZSTD_getFrameContentSize(bytes.data() + kHeaderBytes, bytes.size() - kHeaderBytes),
            ZSTD_CONTENTSIZE_UNKNOWN);
  EXPECT_EQ(DecodeZdepth(bytes), DecodeZdepth(Assemble(HandFrame())));
  RawFrame frame = HandFrame();
  frame.sections[kZeroes].push_back(0);  // the size check must not rely on the frame header
  auto wrong = Assemble(frame, false);
  PutU32(wrong, RawSizeAt(kZeroes), GetU32(wrong, RawSizeAt(kZeroes)) - 1);
  ExpectIoError(wrong, "zstd frame to decompress to 48 bytes");
}

TEST(Zdepth, UnknownPredictorIdsDecodeAsLarger) {
  ZdepthEncodeOptions options;
  options.choose_predictors = false;  // every block uses Larger (0)
  const Image<std::uint16_t> range_mm = HeadLikeImage(64, 48, 3);
  RawFrame frame = Disassemble(EncodeZdepth(range_mm, options));
  std::fill(frame.sections[kBlocks].begin(), frame.sections[kBlocks].end(), std::uint8_t{200});
  EXPECT_EQ(DecodeZdepth(Assemble(frame)), DecodeZdepth(EncodeZdepth(range_mm, options)));
}

TEST(Zdepth, RoundTripsHeadLikeAndRandomImages) {
  for (bool choose : {true, false}) {
    ZdepthEncodeOptions options;
    options.choose_predictors = choose;
    for (unsigned seed = 1; seed <= 4; ++seed) {
      EXPECT_TRUE(DecodesToRoundTrip(HeadLikeImage(128, 96, seed), options)) << seed << choose;
      EXPECT_TRUE(DecodesToRoundTrip(RandomImage(64, 40, seed), options)) << seed << choose;
    }
  }
  // Extremes of the table next to holes: residuals up to +-2039 must still fit in 12 bits.
  std::mt19937 rng(11);
  Image<std::uint16_t> extremes(64, 48);
  const std::array<std::uint16_t, 4> extreme_mm = {0, 201, 11839, 11999};
  for (auto& pixel : extremes.pixels()) pixel = extreme_mm[rng() % 4];
  EXPECT_TRUE(DecodesToRoundTrip(extremes, {}));
  EXPECT_TRUE(DecodesToRoundTrip(Image<std::uint16_t>(24, 16), {}));  // empty Edges/Surfaces
}

TEST(Zdepth, PredictorChoiceChangesTheStreamNotTheImage) {
  const Image<std::uint16_t> range_mm = HeadLikeImage(128, 96, 9);
  ZdepthEncodeOptions fixed;
  fixed.choose_predictors = false;
  const RawFrame chosen = Disassemble(EncodeZdepth(range_mm));
  const RawFrame larger = Disassemble(EncodeZdepth(range_mm, fixed));
  EXPECT_TRUE(std::all_of(larger.sections[kBlocks].begin(), larger.sections[kBlocks].end(),
                          [](std::uint8_t id) { return id == 0; }));
  EXPECT_TRUE(std::any_of(chosen.sections[kBlocks].begin(), chosen.sections[kBlocks].end(),
                          [](std::uint8_t id) { return id != 0; }));
  EXPECT_EQ(DecodeZdepth(Assemble(chosen)), DecodeZdepth(Assemble(larger)));
}

/// Inverse of the quantiser on bucket floors (docs/ahat.md 4.5), so q survives the encoder exactly.
std::uint16_t RangeMmOf(int q) {
  if (q < 550) return static_cast<std::uint16_t>(q + 200);
  if (q < 925) return static_cast<std::uint16_t>(750 + 2 * (q - 550));
  if (q < 1300) return static_cast<std::uint16_t>(1500 + 4 * (q - 925));
  if (q < 1675) return static_cast<std::uint16_t>(3000 + 8 * (q - 1300));
  return static_cast<std::uint16_t>(6000 + 16 * (q - 1675));
}

TEST(Zdepth, TrendPredictorIsSkippedWhereItsResidualOverflows) {
  // Columns linear in y (UpTrend exact, Up off by 100 per pixel), random across x. Column 8 has
  // q = 1, 2039, 1 at y = 6, 7, 8: UpTrend would predict 4077 for (8, 8), a 13-bit residual.
  std::mt19937 rng(5);
  Image<std::uint16_t> range_mm(24, 16);
  for (int u = 0; u < 24; ++u) {
    const int offset = 100 + static_cast<int>(rng() % 400);
    for (int v = 0; v < 16; ++v) range_mm(u, v) = RangeMmOf(offset + 100 * v);
  }
  for (int v = 6; v < 16; ++v) range_mm(8, v) = 0;
  range_mm(8, 6) = RangeMmOf(1);
  range_mm(8, 7) = RangeMmOf(2039);
  range_mm(8, 8) = RangeMmOf(1);
  const RawFrame frame = Disassemble(EncodeZdepth(range_mm));
  EXPECT_NE(frame.sections[kBlocks][0], 3);  // block (1,1) holds (8, 8)
  EXPECT_EQ(frame.sections[kBlocks][1], 3);  // block (2,1) takes the exact UpTrend
  EXPECT_TRUE(DecodesToRoundTrip(range_mm, {}));
}

TEST(Zdepth, EncoderRejectsBadSizesAndOptions) {
  EXPECT_THROW(EncodeZdepth(Image<std::uint16_t>(20, 16)), PreconditionError);
  EXPECT_THROW(EncodeZdepth(Image<std::uint16_t>(16, 16)), PreconditionError);  // 1 block
  ZdepthEncodeOptions options;
  options.zstd_level = 1000;
  EXPECT_THROW(EncodeZdepth(Image<std::uint16_t>(24, 16), options), PreconditionError);
}

TEST(Zdepth, EveryTruncationThrows) {
  const auto bytes = EncodeZdepth(HeadLikeImage(32, 24, 5));
  for (std::size_t length = 0; length < bytes.size(); ++length) {
    ExpectIoError({bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(length)});
  }
  auto longer = bytes;
  longer.push_back(0);
  ExpectIoError(longer, "bytes (40 + compressed sections)");
}

TEST(Zdepth, HeaderErrorsNameTheField) {
  const auto valid = Assemble(HandFrame());
  auto bytes = valid;
  bytes[0] = 0xCB;
  ExpectIoError(bytes, "magic", 0);
  bytes = valid;
  bytes[1] = 0;
  ExpectIoError(bytes, "key frame", 1);
  for (std::size_t at : {4u, 6u}) {
    for (int side : {0, 20, 4104}) {
      bytes = valid;
      bytes[at] = static_cast<std::uint8_t>(side & 0xFF);
      bytes[at + 1] = static_cast<std::uint8_t>(side >> 8);
      ExpectIoError(bytes, "multiples of 8", at);
    }
  }
  ExpectIoError(Assemble(RawFrame{16, 16, {std::vector<std::uint8_t>(32), {0}, {}, {}}}),
                "at least 2");
}

TEST(Zdepth, EverySizeFieldChangeThrows) {
  const auto valid = Assemble(HandFrame());
  for (int s = 0; s < 4; ++s) {
    for (std::size_t at : {RawSizeAt(s), PackedSizeAt(s)}) {
      for (std::int64_t change : {-3, -1, 1, 3, 1 << 20}) {
        auto bytes = valid;
        PutU32(bytes, at, static_cast<std::uint32_t>(GetU32(bytes, at) + change));
        ExpectIoError(bytes);
      }
    }
  }
  auto shifted = valid;  // same total, frames misaligned
  PutU32(shifted, PackedSizeAt(kZeroes), GetU32(shifted, PackedSizeAt(kZeroes)) + 1);
  PutU32(shifted, PackedSizeAt(kBlocks), GetU32(shifted, PackedSizeAt(kBlocks)) - 1);
  ExpectIoError(shifted, "zstd");
}

/// The hand-built frame with one uncompressed section replaced (compressed validly).
std::vector<std::uint8_t> HandFrameWith(int section, std::vector<std::uint8_t> raw) {
  RawFrame frame = HandFrame();
  frame.sections[section] = std::move(raw);
  return Assemble(frame);
}

TEST(Zdepth, SemanticCorruptionThrows) {
  ExpectIoError(Assemble(HandFrame({6, 3})), "PrevFrame");
  ExpectIoError(HandFrameWith(kZeroes, std::vector<std::uint8_t>(49)), "Zeroes size");
  ExpectIoError(HandFrameWith(kEdges, std::vector<std::uint8_t>(20)), "divisible by 3");
  ExpectIoError(HandFrameWith(kSurfaces, Pack12({16, 14})), "more Surfaces values");  // 2 short
  ExpectIoError(HandFrameWith(kSurfaces, Pack12({16, 14, 2, 3, 5, 5})), "Surfaces values");
  for (unsigned first : {1u, 0u}) {  // (1,0) predicted 0: q = -1, then q = 0 for a valid pixel
    std::vector<unsigned> edges = kHandEdges;
    edges[0] = first;
    ExpectIoError(HandFrameWith(kEdges, Pack12(edges)), "quantised values in 1..4095");
  }
  RawFrame frame = HandFrame();
  frame.sections[kZeroes][0] ^= 1;  // pixel 0 turns non-zero: every later pixel flips too
  ExpectIoError(Assemble(frame));
}

TEST(Zdepth, EveryBitFlipThrowsIoErrorOrDecodes) {
  const auto valid = EncodeZdepth(HeadLikeImage(24, 16, 6));
  for (std::size_t bit = 0; bit < valid.size() * 8; ++bit) {
    auto bytes = valid;
    bytes[bit / 8] ^= static_cast<std::uint8_t>(1u << (bit % 8));
    try {
      const Image<std::uint16_t> decoded = DecodeZdepth(bytes);
      EXPECT_EQ(decoded.width(), 24) << bit;
      EXPECT_EQ(decoded.height(), 16) << bit;
    } catch (const IoError&) {
    }
  }
}

}  // namespace
}  // namespace tofnav
