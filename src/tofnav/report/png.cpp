// SPDX-License-Identifier: BSD-3-Clause
// A minimal PNG encoder and base64 (PNG spec, ISO/IEC 15948; RFC 4648).
//
// Our own rather than a library: the report needs only one fixed format (8-bit RGB, one IDAT),
// zlib already supplies deflate and CRC-32, and Debian's libpng would add a dependency for a
// page of code. Decoding is never needed (the browser does it).
#include "tofnav/report/png.hpp"

#include <zlib.h>

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string_view>

#include "tofnav/core/require.hpp"

namespace tofnav {
namespace {

void AppendBigEndian32(std::vector<std::uint8_t>& out, std::uint32_t value) {
  for (int shift = 24; shift >= 0; shift -= 8) {
    out.push_back(static_cast<std::uint8_t>((value >> shift) & 0xFFu));
  }
}

// Length, type, data, then the CRC-32 of type and data.
void AppendChunk(std::vector<std::uint8_t>& out, std::string_view type,
                 std::span<const std::uint8_t> data) {
  AppendBigEndian32(out, static_cast<std::uint32_t>(data.size()));
  const std::size_t type_at = out.size();
  out.insert(out.end(), type.begin(), type.end());
  out.insert(out.end(), data.begin(), data.end());
  const uLong crc =
      crc32(crc32(0L, Z_NULL, 0), out.data() + type_at, static_cast<uInt>(out.size() - type_at));
  AppendBigEndian32(out, static_cast<std::uint32_t>(crc));
}

// Each scanline is filter type 0 (None) then width RGB triples.
std::vector<std::uint8_t> Scanlines(const Image<Rgb8>& image) {
  const auto width = static_cast<std::size_t>(image.width());
  std::vector<std::uint8_t> raw;
  raw.reserve(static_cast<std::size_t>(image.height()) * (1 + 3 * width));
  for (int v = 0; v < image.height(); ++v) {
    raw.push_back(0);
    for (int u = 0; u < image.width(); ++u) {
      const Rgb8& p = image(u, v);
      raw.insert(raw.end(), {p[0], p[1], p[2]});
    }
  }
  return raw;
}

}  // namespace

std::vector<std::uint8_t> EncodePng(const Image<Rgb8>& image) {
  Require(!image.empty(), "EncodePng: empty image");
  const std::vector<std::uint8_t> raw = Scanlines(image);
  Require(raw.size() < std::numeric_limits<uInt>::max() / 2, "EncodePng: image too large");
  uLongf compressed_size = compressBound(static_cast<uLong>(raw.size()));
  std::vector<std::uint8_t> compressed(compressed_size);
  if (compress2(compressed.data(), &compressed_size, raw.data(), static_cast<uLong>(raw.size()),
                Z_BEST_SPEED) != Z_OK) {
    throw std::runtime_error("EncodePng: zlib compress2 failed");
  }
  compressed.resize(compressed_size);

  std::vector<std::uint8_t> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  std::vector<std::uint8_t> header;
  AppendBigEndian32(header, static_cast<std::uint32_t>(image.width()));
  AppendBigEndian32(header, static_cast<std::uint32_t>(image.height()));
  header.insert(header.end(), {8, 2, 0, 0, 0});  // 8 bits, RGB, deflate, filter 0, no interlace
  AppendChunk(png, "IHDR", header);
  AppendChunk(png, "IDAT", compressed);
  AppendChunk(png, "IEND", {});
  return png;
}

std::string Base64Encode(std::span<const std::uint8_t> bytes) {
  constexpr std::string_view kAlphabet =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::size_t n = std::min<std::size_t>(3, bytes.size() - i);
    std::uint32_t group = 0;
    for (std::size_t k = 0; k < 3; ++k) group = (group << 8) | (k < n ? bytes[i + k] : 0u);
    for (std::size_t k = 0; k < 4; ++k) {
      out.push_back(k <= n ? kAlphabet[(group >> (18 - 6 * k)) & 0x3Fu] : '=');
    }
  }
  return out;
}

}  // namespace tofnav
