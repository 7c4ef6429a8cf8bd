// SPDX-License-Identifier: BSD-3-Clause
// Fuzzes the depth_model.json decoder (f_rf files have marker_range_json_fuzz).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "tofnav/casefile/depth_model_json.hpp"
#include "tofnav/io/io_error.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    tofnav::DecodeDepthModelJson(text, "fuzz.json");
  } catch (const tofnav::IoError&) {
  }
  return 0;
}
