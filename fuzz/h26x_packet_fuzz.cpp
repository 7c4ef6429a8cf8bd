// SPDX-License-Identifier: BSD-3-Clause
// libFuzzer target: a live hl2ss H.264 / H.265 stream as the client decodes it (docs/ahat.md
// 3.6.6). The first byte picks the codec, the depth profile and the pose mode; the rest is a run
// of packets, each prefixed by its u16 length, decoded in order by one stream decoder that is
// reset after every error, as Hl2ssAhatClient does.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>

#include "tofnav/io/io_error.hpp"
#include "tofnav/stream/hl2ss_client.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  tofnav::Hl2ssAhatConfig config;
  config.mode = data[0] & 1;
  config.profile_z =
      (data[0] & 2) != 0 ? tofnav::Hl2ssDepthProfile::kZdepth : tofnav::Hl2ssDepthProfile::kSame;
  config.profile_ab = (data[0] & 4) != 0 ? tofnav::Hl2ssVideoProfile::kH265Main
                                         : tofnav::Hl2ssVideoProfile::kH264Main;
  tofnav::Hl2ssVideoDecoder video(config);
  std::span<const std::uint8_t> rest(data + 1, size - 1);
  while (rest.size() >= 2) {
    const std::size_t length = std::min<std::size_t>(rest[0] | (rest[1] << 8), rest.size() - 2);
    const auto packet = rest.subspan(2, length);
    rest = rest.subspan(2 + length);
    try {
      tofnav::DecodeHl2ssPacket(config, packet, "<fuzz>", &video);
    } catch (const tofnav::IoError&) {
      video.Reset();
    }
  }
  return 0;
}
