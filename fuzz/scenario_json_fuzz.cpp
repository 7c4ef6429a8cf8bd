// SPDX-License-Identifier: BSD-3-Clause
// Fuzzes the scenario JSON parser: any input is a scenario or an IoError, nothing else.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "tofnav/io/io_error.hpp"
#include "tofnav/scenario/scenario_json.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  // Mesh heads and shapes read files named in the input; the file readers have their own targets.
  if (text.find("mesh") != std::string_view::npos) return 0;
  try {
    tofnav::ParseScenarioJson(text, "/nonexistent/fuzz.json");
  } catch (const tofnav::IoError&) {
  }
  return 0;
}
