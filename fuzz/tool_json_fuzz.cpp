// SPDX-License-Identifier: BSD-3-Clause
// Fuzzes the tool JSON decoder and the NDI .rom marker import with the same bytes.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "tofnav/casefile/tool_json.hpp"
#include "tofnav/io/io_error.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    tofnav::DecodeToolJson(std::string_view(reinterpret_cast<const char*>(data), size),
                           "fuzz.json");
  } catch (const tofnav::IoError&) {
  }
  try {
    tofnav::DecodeNdiRom(std::span<const std::uint8_t>(data, size), "fuzz.rom");
  } catch (const tofnav::IoError&) {
  }
  return 0;
}
