// SPDX-License-Identifier: BSD-3-Clause
// A recording with its camera, and batched parallel marker detection over its frames (shared by
// track, tool-define, fit-marker-error, pivot and the demo).
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <vector>

#include "tofnav/markers/marker_detection.hpp"
#include "tofnav/sensor/ahat_camera.hpp"
#include "tofnav/sensor/ahat_recording.hpp"
#include "tofnav/tracking/tool_geometry.hpp"

namespace tofnav {

/// A recording and the camera of its calibration.
struct MarkerSource {
  std::unique_ptr<AhatRecording> recording;
  std::unique_ptr<AhatCamera> camera;
  std::size_t frames = 0;  // frames to process (all, or --frames)
};

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
