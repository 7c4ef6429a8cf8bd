// SPDX-License-Identifier: BSD-3-Clause
// hl2ss's AHAT picture packing for the H.264/H.265 profiles and its clients' recovery
// (docs/ahat.md 3.6).
#include "tofnav/recording/hl2ss_video_planes.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>

namespace tofnav {
namespace {

constexpr int kChromaWidth = kAhatWidth / 2;
constexpr double kHalfInfinity = 1e30;  // stands for +inf after the half conversion

/// Rounds a non-negative value to the nearest IEEE binary16 number (11 significant bits), ties to
/// even; values that overflow the format (>= 65520) become kHalfInfinity. Written here because the
/// server's conversion is the ARM instruction's, which no library on the host emulates.
double RoundToHalf(double value) {
  if (value >= 65520.0) return kHalfInfinity;
  if (value < 6.103515625e-05) {  // subnormal halves: steps of 2^-24 (never reached by integers)
    return std::nearbyint(value * 16777216.0) / 16777216.0;
  }
  const int exponent = std::ilogb(value);
  const double step = std::ldexp(1.0, exponent - 10);
  return std::nearbyint(value / step) * step;  // the default FE_TONEAREST rounds ties to even
}

std::array<std::uint8_t, 65536> MakeCodeTable() {
  std::array<std::uint8_t, 65536> table{};
  for (std::size_t x = 0; x < table.size(); ++x) {
    const double half = RoundToHalf(static_cast<double>(x));
    // The square root of a half is never a tie between two halves, so rounding the double root
    // once more gives the half-precision root exactly.
    const double root = half >= kHalfInfinity ? kHalfInfinity : RoundToHalf(std::sqrt(half));
    const double truncated = root >= 65535.0 ? 65535.0 : std::trunc(root);
    table[x] = static_cast<std::uint8_t>(static_cast<unsigned>(truncated) & 0xFFu);
  }
  return table;
}

const std::array<std::uint8_t, 65536>& CodeTable() {
  static const std::array<std::uint8_t, 65536> table = MakeCodeTable();
  return table;
}

// The chroma bytes of the server's NV12 picture, read as one flat array: byte n holds the code of
// AB row n / 256, column 2 (n % 256). In planar 4:2:0, NV12 byte 2 j of chroma row k is U(j, k)
// and byte 2 j + 1 is V(j, k).
template <typename Picture>  // Yuv420Picture or const Yuv420Picture
auto& ChromaByte(Picture& picture, std::size_t n) {
  const auto row = static_cast<int>(n / (2 * kChromaWidth));
  const auto column = static_cast<int>(n % (2 * kChromaWidth));
  return column % 2 == 0 ? picture.u(column / 2, row) : picture.v(column / 2, row);
}

std::uint16_t Squared(std::uint8_t code) {
  return static_cast<std::uint16_t>(static_cast<unsigned>(code) * code);
}

}  // namespace

std::uint8_t Hl2ssAbCode(std::uint16_t ab) { return CodeTable()[ab]; }

Yuv420Picture PackHl2ssSamePicture(const Image<std::uint16_t>& range_mm,
                                   const Image<std::uint16_t>& ab) {
  Yuv420Picture picture;
  const std::span<const std::uint16_t> range = range_mm.pixels();
  std::span<std::uint8_t> y = picture.y.pixels();
  for (std::size_t i = 0; i < range.size(); ++i) {
    const unsigned valid = range[i] < kAhatInvalidRange ? range[i] : 0u;
    y[i] = static_cast<std::uint8_t>((valid >> 2) & 0xFFu);  // wraps at 1024 mm, as the server
  }
  const auto& table = CodeTable();
  std::size_t n = 0;
  for (int row = 0; row < kAhatHeight; ++row) {
    for (int column = 0; column < kAhatWidth; column += 2, ++n) {
      ChromaByte(picture, n) = table[ab(column, row)];
    }
  }
  return picture;
}

Yuv420Picture PackHl2ssZdepthPicture(const Image<std::uint16_t>& ab) {
  Yuv420Picture picture;
  const auto& table = CodeTable();
  const std::span<const std::uint16_t> in = ab.pixels();
  std::span<std::uint8_t> y = picture.y.pixels();
  for (std::size_t i = 0; i < in.size(); ++i) y[i] = table[in[i]];
  std::fill(picture.u.pixels().begin(), picture.u.pixels().end(), std::uint8_t{128});
  std::fill(picture.v.pixels().begin(), picture.v.pixels().end(), std::uint8_t{128});
  return picture;
}

void UnpackHl2ssSamePicture(const Yuv420Picture& picture, Image<std::uint16_t>& range_mm,
                            Image<std::uint16_t>& ab) {
  // Every pixel is written below: images of the right size are reused, not cleared.
  for (Image<std::uint16_t>* image : {&range_mm, &ab}) {
    if (image->width() != kAhatWidth || image->height() != kAhatHeight) {
      *image = Image<std::uint16_t>(kAhatWidth, kAhatHeight);
    }
  }
  const std::span<const std::uint8_t> y = picture.y.pixels();
  std::span<std::uint16_t> range = range_mm.pixels();
  for (std::size_t i = 0; i < y.size(); ++i) range[i] = static_cast<std::uint16_t>(4u * y[i]);
  std::size_t n = 0;
  for (int row = 0; row < kAhatHeight; ++row) {
    for (int column = 0; column < kAhatWidth; column += 2, ++n) {
      const std::uint16_t value = Squared(ChromaByte(picture, n));
      ab(column, row) = value;
      ab(column + 1, row) = value;
    }
  }
}

Image<std::uint16_t> UnpackHl2ssZdepthAb(const Yuv420Picture& picture) {
  Image<std::uint16_t> ab(kAhatWidth, kAhatHeight);
  const std::span<const std::uint8_t> y = picture.y.pixels();
  std::span<std::uint16_t> out = ab.pixels();
  for (std::size_t i = 0; i < y.size(); ++i) out[i] = Squared(y[i]);
  return ab;
}

}  // namespace tofnav
