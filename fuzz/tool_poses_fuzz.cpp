// SPDX-License-Identifier: BSD-3-Clause
// Fuzzes the tool poses decoder (CSV and JSON, chosen by the first byte).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "tofnav/casefile/tool_poses_io.hpp"
#include "tofnav/io/io_error.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    tofnav::DecodeToolPoses(std::string_view(reinterpret_cast<const char*>(data), size),
                            "fuzz.csv");
  } catch (const tofnav::IoError&) {
  }
  return 0;
}
