// SPDX-License-Identifier: BSD-3-Clause
// libFuzzer target: 16-bit P5 PGM decoding of arbitrary bytes; a decoded image must re-encode.
#include <cstddef>
#include <cstdint>
#include <span>

#include "tofnav/io/io_error.hpp"
#include "tofnav/recording/pgm.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const tofnav::Image<std::uint16_t> image =
        tofnav::DecodePgm16(std::span<const std::uint8_t>(data, size), "<fuzz>", 0);
    // The encoder writes the canonical header, so decode(encode(x)) must give x back.
    if (tofnav::DecodePgm16(tofnav::EncodePgm16(image)) != image) __builtin_trap();
  } catch (const tofnav::IoError&) {
  }
  return 0;
}
