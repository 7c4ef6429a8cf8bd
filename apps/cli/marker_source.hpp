// SPDX-License-Identifier: BSD-3-Clause
// The recording options shared by the marker commands (track, tool-define, fit-marker-error,
// pivot): <recording>, --calibration, --sample-offset, --frames and the detection thresholds.
#pragma once

#include <CLI/CLI.hpp>
#include <filesystem>
#include <optional>

#include "tofnav/markers/marker_detection.hpp"
#include "tofnav/pipeline/marker_frames.hpp"

namespace tofnav {

/// Command-line options shared by the marker commands.
struct MarkerSourceArgs {
  std::filesystem::path recording;
  std::filesystem::path calibration;  // empty: the recording's own (StreamRecorder)
  std::optional<double> sample_offset_px;
  std::optional<std::size_t> frames;
  MarkerDetectionOptions detection;
  /// Adds <recording> (unless `with_recording` is false), --calibration, --sample-offset,
  /// --frames, --ab-threshold, --relative-threshold.
  void AddTo(CLI::App& app, bool with_recording = true);
};

/// Opens the recording and builds the camera (hl2ss needs --calibration). Throws on failure.
MarkerSource OpenMarkerSource(const MarkerSourceArgs& args);

}  // namespace tofnav
