// SPDX-License-Identifier: BSD-3-Clause
// A recorded AHAT stream, whatever its container: frames read one at a time, never the whole file.
// The interface only: stages and compositions consume frames without knowing files; the
// containers (hl2ss, StreamRecorder) and OpenAhatRecording are in recording/.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "tofnav/sensor/ahat_calibration.hpp"
#include "tofnav/sensor/ahat_frame.hpp"

namespace tofnav {

/// Read-only access to a recording. Implementations index the frames on open (offsets and
/// timestamps only) and decode one frame per ReadFrame call. Not thread-safe for one object.
class AhatRecording {
 public:
  virtual ~AhatRecording() = default;

  /// "hl2ss RAW", "hl2ss ZDEPTH", "StreamRecorder", ...
  virtual std::string format() const = 0;
  virtual std::size_t frame_count() const = 0;
  /// Host ticks of frame `index` (100 ns), in recording order (non-decreasing).
  virtual std::uint64_t host_ticks(std::size_t index) const = 0;
  /// Decodes frame `index`; IoError naming the file and offset on corrupt data.
  virtual AhatFrame ReadFrame(std::size_t index) const = 0;
  /// The calibration stored with the recording (StreamRecorder), or nullopt (hl2ss keeps it in
  /// a separate folder).
  virtual std::optional<AhatCalibration> calibration() const = 0;

  /// Index of the frame whose timestamp is nearest to `host_ticks` (ties: the earlier frame).
  std::size_t NearestFrame(std::uint64_t host_ticks) const;
};

}  // namespace tofnav
