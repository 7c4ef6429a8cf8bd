// SPDX-License-Identifier: BSD-3-Clause
// libFuzzer target: one live hl2ss packet as the client receives it (12-byte header, payload,
// pose), under a configuration chosen by the first byte, and the client's config decoder.
#include <cstddef>
#include <cstdint>
#include <span>

#include "tofnav/io/io_error.hpp"
#include "tofnav/stream/hl2ss_client.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::span<const std::uint8_t> bytes(data + 1, size - 1);
  tofnav::Hl2ssAhatConfig config;
  config.mode = data[0] & 1;
  config.profile_z =
      (data[0] & 2) != 0 ? tofnav::Hl2ssDepthProfile::kZdepth : tofnav::Hl2ssDepthProfile::kSame;
  try {
    tofnav::DecodeHl2ssPacket(config, bytes, "<fuzz>");
  } catch (const tofnav::IoError&) {
  }
  try {
    tofnav::DecodeHl2ssAhatConfig(bytes, "<fuzz>");
  } catch (const tofnav::IoError&) {
  }
  return 0;
}
