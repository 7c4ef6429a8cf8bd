// SPDX-License-Identifier: BSD-3-Clause
// Recording + camera, tool files and batched parallel marker detection for the marker commands.
#include "marker_frames.hpp"

#include <algorithm>
#include <cctype>
#include <stdexcept>

#include "tofnav/core/parallel_for.hpp"
#include "tofnav/io/hl2ss_calibration.hpp"
#include "tofnav/io/tool_json.hpp"

namespace tofnav {
namespace {

constexpr std::size_t kBatchFrames = 16;  // frames decoded before one parallel detection pass

}  // namespace

void MarkerSourceArgs::AddTo(CLI::App& app, bool with_recording) {
  if (with_recording) {
    app.add_option("recording", recording, "AHAT recording (hl2ss .bin or StreamRecorder folder)")
        ->required();
  }
  app.add_option("--calibration", calibration,
                 "hl2ss calibration folder (required for hl2ss recordings)");
  app.add_option("--sample-offset", sample_offset_px,
                 "LUT sample offset of the calibration (0 or 0.5; default: auto rule)");
  app.add_option("--frames", frames, "process only the first N frames")->check(CLI::PositiveNumber);
  app.add_option("--ab-threshold", detection.ab_threshold,
                 "AB threshold of marker pixels [counts] (default 1280)");
  app.add_option("--relative-threshold", detection.relative_threshold,
                 "adaptive threshold factor over the 99.9th AB percentile (0 = off)");
}

MarkerSource OpenMarkerSource(const MarkerSourceArgs& args) {
  MarkerSource source;
  source.recording = OpenAhatRecording(args.recording);
  std::optional<AhatCalibration> calibration;
  if (!args.calibration.empty()) {
    calibration = ReadHl2ssCalibration(args.calibration, args.sample_offset_px);
  } else {
    calibration = source.recording->calibration();
  }
  if (!calibration) {
    throw std::runtime_error(args.recording.string() +
                             " has no calibration of its own: give --calibration DIR");
  }
  source.camera = std::make_unique<AhatCamera>(*calibration);
  source.frames = source.recording->frame_count();
  if (args.frames) source.frames = std::min(source.frames, *args.frames);
  args.detection.Check();
  return source;
}

ToolGeometry ReadToolFile(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".rom" ? ReadNdiRom(path) : ReadToolJson(path);
}

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
