// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/io/ahat_recording.hpp"

#include <array>
#include <string_view>

#include "tofnav/core/require.hpp"
#include "tofnav/io/file.hpp"
#include "tofnav/io/hl2ss_recording.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/io/stream_recorder.hpp"

namespace tofnav {

std::size_t AhatRecording::NearestFrame(std::uint64_t ticks) const {
  const std::size_t n = frame_count();
  Require(n > 0, "NearestFrame on an empty recording");
  // Binary search on the non-decreasing timestamps.
  std::size_t lo = 0;
  std::size_t hi = n;
  while (lo < hi) {
    const std::size_t mid = lo + (hi - lo) / 2;
    if (host_ticks(mid) < ticks) {
      lo = mid + 1;
    } else {
      hi = mid;
    }
  }
  if (lo == n) return n - 1;
  if (lo == 0) return 0;
  return (ticks - host_ticks(lo - 1) <= host_ticks(lo) - ticks) ? lo - 1 : lo;
}

std::unique_ptr<AhatRecording> OpenAhatRecording(const std::filesystem::path& path) {
  if (std::filesystem::is_directory(path)) {
    if (!std::filesystem::exists(path / kStreamRecorderTar)) {
      throw IoError(path, std::nullopt,
                    std::string("a folder, but not a StreamRecorder capture: expected '") +
                        kStreamRecorderTar + "' in it");
    }
    return StreamRecorderCapture::Open(path);
  }
  const RandomAccessFile file(path);
  std::array<std::uint8_t, 8> magic{};
  if (file.size() >= magic.size()) file.ReadAt(0, magic, "magic");
  const std::string_view text(reinterpret_cast<const char*>(magic.data()), magic.size());
  if (text == "HL2SSV23") return OpenHl2ssRecording(path);
  if (text == "X38HL2SS" || text == "V02HL2SS") {
    throw IoError(path, 0,
                  "hl2ss recording from before v1.0.25 (magic " + std::string(text) +
                      "): not supported; re-record with hl2ss >= v1.0.25 (HL2SSV23)");
  }
  throw IoError(path, 0,
                "not an AHAT recording: expected the hl2ss magic 'HL2SSV23' or a StreamRecorder "
                "capture folder");
}

}  // namespace tofnav
