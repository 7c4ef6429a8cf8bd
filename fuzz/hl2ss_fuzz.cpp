// SPDX-License-Identifier: BSD-3-Clause
// libFuzzer target: the hl2ss AHAT recording reader over arbitrary bytes, every frame decoded.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "tofnav/io/io_error.hpp"
#include "tofnav/recording/hl2ss_recording.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const tofnav::Hl2ssRecording recording(std::vector<std::uint8_t>(data, data + size),
                                           "fuzz.bin");
    for (std::size_t i = 0; i < recording.frame_count(); ++i) {
      try {
        const tofnav::AhatFrame frame = recording.ReadFrame(i);
        (void)frame;
      } catch (const tofnav::IoError&) {
        // a corrupt frame is an expected outcome; the others may still decode
      }
      (void)recording.NearestFrame(recording.host_ticks(i));
    }
  } catch (const tofnav::IoError&) {
    // malformed file: expected
  }
  return 0;
}
