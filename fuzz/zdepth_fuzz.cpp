// SPDX-License-Identifier: BSD-3-Clause
// libFuzzer target: DecodeZdepth must throw IoError or return a valid image, never crash.
#include <zstd.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "tofnav/io/io_error.hpp"
#include "tofnav/recording/zdepth.hpp"

namespace {

constexpr std::size_t kHeaderBytes = 40;

void PutU32(std::vector<std::uint8_t>& bytes, std::size_t at, std::size_t value) {
  for (std::size_t k = 0; k < 4; ++k) bytes[at + k] = static_cast<std::uint8_t>(value >> (8 * k));
}

/// Header + the four sections uncompressed (split by the header's uncompressed sizes, clipped
/// to the input) -> a frame with valid zstd frames, so mutations reach the block walk.
std::vector<std::uint8_t> CompressSections(std::span<const std::uint8_t> input) {
  std::vector<std::uint8_t> frame(input.begin(), input.begin() + kHeaderBytes);
  std::size_t at = kHeaderBytes;
  for (std::size_t s = 0; s < 4; ++s) {
    std::size_t raw = 0;
    for (std::size_t k = 0; k < 4; ++k) raw |= std::size_t{frame[8 + 8 * s + k]} << (8 * k);
    raw = std::min(raw, input.size() - at);
    std::vector<std::uint8_t> packed(ZSTD_compressBound(raw));
    const std::size_t size = ZSTD_compress(packed.data(), packed.size(), input.data() + at, raw, 1);
    if (ZSTD_isError(size)) __builtin_trap();
    PutU32(frame, 8 + 8 * s, raw);
    PutU32(frame, 12 + 8 * s, size);
    frame.insert(frame.end(), packed.begin(), packed.begin() + static_cast<std::ptrdiff_t>(size));
    at += raw;
  }
  return frame;
}

}  // namespace

// First byte even: the rest is a stored Zdepth frame. Odd: the rest is a header followed by the
// uncompressed sections (see CompressSections).
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::span<const std::uint8_t> input(data + 1, size - 1);
  std::vector<std::uint8_t> compressed;
  if ((data[0] & 1) != 0) {
    if (input.size() < kHeaderBytes) return 0;
    compressed = CompressSections(input);
  }
  try {
    const tofnav::Image<std::uint16_t> image = tofnav::DecodeZdepth(
        compressed.empty() ? input : std::span<const std::uint8_t>(compressed));
    if (image.empty() || image.width() % 8 != 0 || image.height() % 8 != 0) __builtin_trap();
  } catch (const tofnav::IoError&) {
  }
  return 0;
}
