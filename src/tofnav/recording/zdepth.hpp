// SPDX-License-Identifier: BSD-3-Clause
// Zdepth key-frame codec (the hl2ss ZDEPTH profile), our own implementation on libzstd from the
// bitstream description in docs/ahat.md section 4.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <vector>

#include "tofnav/core/image.hpp"

namespace tofnav {

struct ZdepthEncodeOptions {
  int zstd_level = 1;  // the reference encoder uses 1
  /// Pick the interior-block predictor with the smallest residual sum (as the reference does);
  /// false uses predictor 0 everywhere (faster, larger).
  bool choose_predictors = true;
  void Check() const;
};

/// Encodes a range image [mm] (0 = invalid) as one Zdepth key frame. Lossy as the format is:
/// d <= 200 mm -> 0, exact 201..749 mm, 2 mm floor steps 750..1499, coarser above (docs/ahat.md
/// 4.5). Width and height must be multiples of 8 up to 4096 with (W/8 - 1) * (H/8 - 1) >= 2 (the
/// decoder's rule), else PreconditionError.
std::vector<std::uint8_t> EncodeZdepth(const Image<std::uint16_t>& range_mm,
                                       const ZdepthEncodeOptions& options = {});

/// Decodes one Zdepth key frame into a range image [mm]. Throws IoError naming `source`, the
/// byte offset `base_offset` + position, and what was expected, on any malformed input. Errors
/// inside a decompressed section name the offset of that section's zstd frame.
Image<std::uint16_t> DecodeZdepth(std::span<const std::uint8_t> bytes,
                                  const std::filesystem::path& source = "<zdepth>",
                                  std::uint64_t base_offset = 0);

/// The value the codec reproduces for `range_mm` (quantise then dequantise).
std::uint16_t ZdepthRoundTripMm(std::uint16_t range_mm);

}  // namespace tofnav
