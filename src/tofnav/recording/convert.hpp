// SPDX-License-Identifier: BSD-3-Clause
// Re-writes an AHAT recording in another container (hl2ss RAW or ZDEPTH, StreamRecorder).
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <optional>

#include "tofnav/sensor/ahat_recording.hpp"

namespace tofnav {

enum class RecordingFormat { kHl2ssRaw, kHl2ssZdepth, kStreamRecorder };

struct ConvertOptions {
  RecordingFormat format = RecordingFormat::kHl2ssRaw;
  /// Needed for StreamRecorder output (its LUT) when the input carries none (hl2ss). A table
  /// sampled at s = 0 is re-sampled at pixel centres (the LUT's definition) through AhatCamera.
  std::optional<AhatCalibration> calibration;
  /// Called after each frame with (frames done, total).
  std::function<void(std::size_t, std::size_t)> progress;
};

struct ConvertResult {
  std::size_t frames_written = 0;
  std::size_t frames_with_pose = 0;
};

/// Copies every frame of `input` into `output` (a .bin file for hl2ss, a folder for
/// StreamRecorder). Timestamps are copied as they are: hl2ss QPC ticks and StreamRecorder
/// FILETIME are both 100 ns, so intervals are kept but absolute times keep their origin. ZDEPTH
/// output quantises depth as the format does (exact 201-749 mm). Writes are atomic.
ConvertResult ConvertRecording(const AhatRecording& input, const std::filesystem::path& output,
                               const ConvertOptions& options);

}  // namespace tofnav
