// SPDX-License-Identifier: BSD-3-Clause
// libFuzzer target: the OpenIGTLink receiver (what any network peer sends the server), fed in
// chunks whose sizes the first byte chooses, and the content decoders on what it delivers.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "tofnav/io/io_error.hpp"
#include "tofnav/stream/igtl_receiver.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::size_t chunk = 1 + data[0] % 97;
  std::span<const std::uint8_t> bytes(data + 1, size - 1);
  tofnav::IgtlReceiver receiver("<fuzz>", {.max_body_bytes = 1 << 20, .max_kept_bytes = 1 << 16});
  const auto on_frame = [](const tofnav::IgtlFrame& f) {
    if (f.content.size() > (1 << 20)) std::abort();
    try {
      if (f.header.type == "TRANSFORM") tofnav::DecodeIgtlTransformContent(f.content);
      if (f.header.type == "STRING") tofnav::DecodeIgtlStringContent(f.content);
    } catch (const tofnav::IoError&) {
    }
  };
  try {
    while (!bytes.empty()) {
      const std::size_t n = std::min(chunk, bytes.size());
      receiver.Feed(bytes.first(n), on_frame);
      bytes = bytes.subspan(n);
    }
  } catch (const tofnav::IoError&) {
  }
  return 0;
}
