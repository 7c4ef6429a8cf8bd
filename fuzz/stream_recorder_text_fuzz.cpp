// SPDX-License-Identifier: BSD-3-Clause
// libFuzzer target: StreamRecorder extrinsics and rig2world text parsers over arbitrary bytes.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "tofnav/io/io_error.hpp"
#include "tofnav/recording/stream_recorder_files.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    tofnav::ParseStreamRecorderExtrinsics(text, "<fuzz>");
  } catch (const tofnav::IoError&) {
  }
  try {
    tofnav::ParseStreamRecorderRig2World(text, "<fuzz>");
  } catch (const tofnav::IoError&) {
  }
  return 0;
}
