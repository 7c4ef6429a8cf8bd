// SPDX-License-Identifier: BSD-3-Clause
// A minimal PNG encoder (8-bit RGB, no interlace) and base64, to embed renderings in the report.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "tofnav/core/image.hpp"
#include "tofnav/core/point_cloud.hpp"

namespace tofnav {

/// The whole PNG file: signature, IHDR (colour type 2, 8 bits), one zlib IDAT of the
/// unfiltered scanlines, IEND. Throws PreconditionError for an empty image.
std::vector<std::uint8_t> EncodePng(const Image<Rgb8>& image);

/// RFC 4648 base64 with padding (for data: URIs).
std::string Base64Encode(std::span<const std::uint8_t> bytes);

}  // namespace tofnav
