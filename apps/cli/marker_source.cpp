// SPDX-License-Identifier: BSD-3-Clause
#include "marker_source.hpp"

#include <algorithm>
#include <utility>

#include "tofnav/recording/open_recording.hpp"

namespace tofnav {

void MarkerSourceArgs::AddTo(CLI::App& app, bool with_recording) {
  if (with_recording) {
    app.add_option("recording", recording, "AHAT recording (hl2ss .bin or StreamRecorder folder)")
        ->required();
  }
  app.add_option("--calibration", calibration,
                 "hl2ss calibration folder (required for hl2ss recordings)");
  app.add_option("--sample-offset", sample_offset_px,
                 "LUT sample offset of the calibration (0 or 0.5; unset: auto rule)");
  app.add_option("--frames", frames, "process only the first N frames")->check(CLI::PositiveNumber);
  app.add_option("--ab-threshold", detection.ab_threshold,
                 "AB threshold of marker pixels [counts]");
  app.add_option("--relative-threshold", detection.relative_threshold,
                 "adaptive threshold factor over the 99.9th AB percentile (0 = off)");
}

MarkerSource OpenMarkerSource(const MarkerSourceArgs& args) {
  RecordingWithCamera opened =
      OpenRecordingWithCamera(args.recording, args.calibration, args.sample_offset_px);
  MarkerSource source;
  source.recording = std::move(opened.recording);
  source.camera = std::move(opened.camera);
  source.frames = source.recording->frame_count();
  if (args.frames) source.frames = std::min(source.frames, *args.frames);
  args.detection.Check();
  return source;
}

}  // namespace tofnav
