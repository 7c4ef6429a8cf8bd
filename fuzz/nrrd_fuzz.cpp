// SPDX-License-Identifier: BSD-3-Clause
// libFuzzer target: NRRD header and attached data (raw or gzip) decoded from memory.
#include <cstddef>
#include <cstdint>
#include <span>

#include "tofnav/io/io_error.hpp"
#include "tofnav/volume/nrrd.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    // No data folder: detached `data file:` entries are refused, never opened.
    const tofnav::CtVolume volume = tofnav::DecodeNrrd(std::span(data, size), "fuzz.nrrd");
    volume.Check();  // a decoded volume must be valid (PreconditionError would crash here)
  } catch (const tofnav::IoError&) {
    // malformed input: the expected outcome
  }
  return 0;
}
