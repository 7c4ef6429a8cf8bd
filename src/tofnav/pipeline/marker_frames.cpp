// SPDX-License-Identifier: BSD-3-Clause
// Batched parallel marker detection over a recording.
#include "tofnav/pipeline/marker_frames.hpp"

#include <algorithm>

#include "tofnav/core/frame_batches.hpp"

namespace tofnav {
namespace {

constexpr std::size_t kMarkerBatchFrames = 16;  // frames decoded before one parallel detection pass

}  // namespace

void ForEachFrameDetections(
    const MarkerSource& source, const MarkerDetectionOptions& options,
    const std::function<void(std::size_t, const AhatFrame&, MarkerDetectionResult&)>& sink,
    const std::function<void(std::size_t, std::size_t)>& progress) {
  struct Item {
    AhatFrame frame;
    MarkerDetectionResult detection;
  };
  ForEachInBatches<Item>(
      source.frames, kMarkerBatchFrames,
      [&](std::size_t i) {
        return Item{source.recording->ReadFrame(i), {}};
      },
      [&](Item& item, std::size_t) {
        item.detection = LocateMarkers(item.frame, *source.camera, options);
      },
      [&](Item& item, std::size_t i) {
        sink(i, item.frame, item.detection);
        if (progress) progress(i + 1, source.frames);
      });
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
