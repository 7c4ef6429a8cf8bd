// SPDX-License-Identifier: BSD-3-Clause
// Batched parallel marker detection over a recording.
#include "tofnav/pipeline/marker_frames.hpp"

#include <algorithm>

#include "tofnav/core/parallel_for.hpp"

namespace tofnav {
namespace {

constexpr std::size_t kBatchFrames = 16;  // frames decoded before one parallel detection pass

}  // namespace

void ForEachFrameDetections(
    const MarkerSource& source, const MarkerDetectionOptions& options,
    const std::function<void(std::size_t, const AhatFrame&, MarkerDetectionResult&)>& sink,
    const std::function<void(std::size_t, std::size_t)>& progress) {
  std::vector<AhatFrame> frames;
  std::vector<MarkerDetectionResult> detections;
  for (std::size_t first = 0; first < source.frames; first += kBatchFrames) {
    const std::size_t count = std::min(kBatchFrames, source.frames - first);
    frames.clear();
    for (std::size_t i = 0; i < count; ++i)
      frames.push_back(source.recording->ReadFrame(first + i));
    detections.assign(count, {});
    ParallelFor(0, static_cast<std::int64_t>(count), [&](std::int64_t i) {
      const auto k = static_cast<std::size_t>(i);
      detections[k] = LocateMarkers(frames[k], *source.camera, options);
    });
    for (std::size_t i = 0; i < count; ++i) {
      sink(first + i, frames[i], detections[i]);
      if (progress) progress(first + i + 1, source.frames);
    }
  }
}

void ForEachFrameMarkers(
    const MarkerSource& source, const MarkerDetectionOptions& options,
    const std::function<void(std::size_t, const AhatFrame&, std::vector<DetectedMarker>&)>& sink,
    const std::function<void(std::size_t, std::size_t)>& progress) {
  ForEachFrameDetections(
      source, options,
      [&](std::size_t index, const AhatFrame& frame, MarkerDetectionResult& detection) {
        sink(index, frame, detection.markers);
      },
      progress);
}

}  // namespace tofnav
