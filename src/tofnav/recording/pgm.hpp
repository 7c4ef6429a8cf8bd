// SPDX-License-Identifier: BSD-3-Clause
// Binary 16-bit PGM (P5, maxval 65535, big-endian samples), as StreamRecorder stores AHAT frames.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <vector>

#include "tofnav/core/image.hpp"

namespace tofnav {

/// Decodes a P5 image with maxval 65535. The header is parsed generically (whitespace and `#`
/// comments between the magic, width, height and maxval; one whitespace byte before the samples)
/// and the sample bytes must be exactly width * height * 2. The caller checks the size it needs.
/// Throws IoError naming `source` and the absolute offset `base_offset` + position.
Image<std::uint16_t> DecodePgm16(std::span<const std::uint8_t> bytes,
                                 const std::filesystem::path& source = "<pgm>",
                                 std::uint64_t base_offset = 0);

/// Encodes as "P5\n<width> <height>\n65535\n" plus big-endian samples (the StreamRecorder
/// header: 17 bytes for 512 x 512). PreconditionError on an empty image.
std::vector<std::uint8_t> EncodePgm16(const Image<std::uint16_t>& image);

}  // namespace tofnav
