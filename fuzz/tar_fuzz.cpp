// SPDX-License-Identifier: BSD-3-Clause
// libFuzzer target: ustar index over arbitrary bytes, then a 16-bit PGM decode of every entry.
#include <cstddef>
#include <cstdint>
#include <span>

#include "tofnav/io/io_error.hpp"
#include "tofnav/io/tar.hpp"
#include "tofnav/recording/pgm.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> bytes(data, size);
  for (const bool tolerant : {true, false}) {
    try {
      const tofnav::TarIndex index =
          tofnav::IndexTar(bytes, "<fuzz>", {.allow_truncated_tail = tolerant});
      for (const tofnav::TarEntry& entry : index.entries) {
        if (entry.data_offset > size || entry.size > size - entry.data_offset) __builtin_trap();
        try {
          tofnav::DecodePgm16(bytes.subspan(entry.data_offset, entry.size), "<fuzz>",
                              entry.data_offset);
        } catch (const tofnav::IoError&) {
        }
      }
    } catch (const tofnav::IoError&) {
    }
  }
  return 0;
}
