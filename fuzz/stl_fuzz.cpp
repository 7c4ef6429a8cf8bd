// SPDX-License-Identifier: BSD-3-Clause
// libFuzzer target: DecodeStl (binary and ASCII) on arbitrary bytes.
#include <cstdint>
#include <span>

#include "tofnav/io/io_error.hpp"
#include "tofnav/mesh/mesh_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    tofnav::DecodeStl(std::span<const std::uint8_t>(data, size), "fuzz.stl").CheckConsistent();
  } catch (const tofnav::IoError&) {
    return 0;  // malformed input is expected to be refused
  }
  return 0;
}
