// SPDX-License-Identifier: BSD-3-Clause
// Shared by track, tool-define and fit-marker-error: recording + camera, tool files, detections.
#pragma once

#include <CLI/CLI.hpp>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "tofnav/io/ahat_recording.hpp"
#include "tofnav/markers/marker_detection.hpp"
#include "tofnav/sensor/ahat_camera.hpp"
#include "tofnav/tracking/tool_geometry.hpp"

namespace tofnav {

/// A recording and the camera of its calibration.
struct MarkerSource {
  std::unique_ptr<AhatRecording> recording;
  std::unique_ptr<AhatCamera> camera;
  std::size_t frames = 0;  // frames to process (all, or --frames)
};

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

/// A tool file: NDI .rom (by extension) or tool JSON.
ToolGeometry ReadToolFile(const std::filesystem::path& path);

/// Reads frames 0 .. source.frames - 1 in order, detects markers in parallel batches, and calls
/// sink(index, frame, detection) in frame order; progress(done, total) after each frame.
void ForEachFrameDetections(
    const MarkerSource& source, const MarkerDetectionOptions& options,
    const std::function<void(std::size_t, const AhatFrame&, MarkerDetectionResult&)>& sink,
    const std::function<void(std::size_t, std::size_t)>& progress);

/// ForEachFrameDetections with the markers only: sink(index, frame, markers).
void ForEachFrameMarkers(
    const MarkerSource& source, const MarkerDetectionOptions& options,
    const std::function<void(std::size_t, const AhatFrame&, std::vector<DetectedMarker>&)>& sink,
    const std::function<void(std::size_t, std::size_t)>& progress);

}  // namespace tofnav
