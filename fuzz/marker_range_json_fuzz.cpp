// SPDX-License-Identifier: BSD-3-Clause
// Fuzzes the f_rf curve JSON decoder; a decoded curve is evaluated and applied (Eq. 2).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "tofnav/casefile/marker_range_json.hpp"
#include "tofnav/io/io_error.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const tofnav::MarkerRangeFile file = tofnav::DecodeMarkerRangeJson(
        std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.json");
    for (double d = 100.0; d < 1000.0; d += 50.0) (void)tofnav::CorrectMarkerRange(d, file.model);
  } catch (const tofnav::IoError&) {
  }
  return 0;
}
