// SPDX-License-Identifier: BSD-3-Clause
// Opens an AHAT recording file or folder, whatever its container.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "tofnav/sensor/ahat_camera.hpp"
#include "tofnav/sensor/ahat_recording.hpp"

namespace tofnav {

/// Opens an hl2ss `.bin` file (magic HL2SSV23) or a StreamRecorder capture folder
/// (`Depth AHaT.tar`), telling them apart by content; IoError when it is neither.
std::unique_ptr<AhatRecording> OpenAhatRecording(const std::filesystem::path& path);

/// A recording and the camera of its calibration.
struct RecordingWithCamera {
  std::unique_ptr<AhatRecording> recording;
  std::unique_ptr<AhatCamera> camera;
};

/// Opens `path` (OpenAhatRecording) and builds the camera from the hl2ss calibration folder
/// `calibration_dir` (LUT sample offset `sample_offset_px`, default: the auto rule) or, when
/// `calibration_dir` is empty, from the recording's own calibration; std::runtime_error when there
/// is none.
RecordingWithCamera OpenRecordingWithCamera(const std::filesystem::path& path,
                                            const std::filesystem::path& calibration_dir,
                                            std::optional<double> sample_offset_px = std::nullopt);

/// Why `recording`'s range is too coarse for the stages that measure depth (f_rf, the depth model,
/// reconstruction): hl2ss SAME + H.264/H.265 (4 mm steps, codec noise, wrapping above 1023 mm);
/// nullopt for every other recording. The text names the file's profile, the cost and what to
/// stream instead (docs/ahat.md 3.6.5).
std::optional<std::string> LossyDepthReason(const AhatRecording& recording);

/// Throws std::runtime_error "<path>: <reason>; pass --allow-lossy-depth to use it anyway" when
/// LossyDepthReason says so and `allow` is false.
void RefuseLossyDepth(const AhatRecording& recording, const std::filesystem::path& path,
                      bool allow);

}  // namespace tofnav
