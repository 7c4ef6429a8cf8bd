// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/recording/open_recording.hpp"

#include <array>
#include <stdexcept>
#include <string_view>

#include "tofnav/io/file.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/recording/hl2ss_calibration.hpp"
#include "tofnav/recording/hl2ss_format.hpp"
#include "tofnav/recording/hl2ss_recording.hpp"
#include "tofnav/recording/stream_recorder.hpp"

namespace tofnav {

std::unique_ptr<AhatRecording> OpenAhatRecording(const std::filesystem::path& path) {
  if (std::filesystem::is_directory(path)) {
    if (!std::filesystem::exists(path / kStreamRecorderTar)) {
      throw IoError(path, std::nullopt,
                    std::string("a folder, but not a StreamRecorder capture: expected '") +
                        kStreamRecorderTar + "' in it");
    }
    return StreamRecorderCapture::Open(path);
  }
  const RandomAccessFile file(path);
  std::array<std::uint8_t, 8> magic{};
  if (file.size() >= magic.size()) file.ReadAt(0, magic, "magic");
  const std::string_view text(reinterpret_cast<const char*>(magic.data()), magic.size());
  if (text == "HL2SSV23") return OpenHl2ssRecording(path);
  if (text == "X38HL2SS" || text == "V02HL2SS") {
    throw IoError(path, 0,
                  "hl2ss recording from before v1.0.25 (magic " + std::string(text) +
                      "): not supported; re-record with hl2ss >= v1.0.25 (HL2SSV23)");
  }
  throw IoError(path, 0,
                "not an AHAT recording: expected the hl2ss magic 'HL2SSV23' or a StreamRecorder "
                "capture folder");
}

RecordingWithCamera OpenRecordingWithCamera(const std::filesystem::path& path,
                                            const std::filesystem::path& calibration_dir,
                                            std::optional<double> sample_offset_px) {
  RecordingWithCamera opened;
  opened.recording = OpenAhatRecording(path);
  std::optional<AhatCalibration> calibration;
  if (!calibration_dir.empty()) {
    calibration = ReadHl2ssCalibration(calibration_dir, sample_offset_px);
  } else {
    calibration = opened.recording->calibration();
  }
  if (!calibration) {
    throw std::runtime_error(path.string() +
                             " has no calibration of its own: give --calibration DIR");
  }
  opened.camera = std::make_unique<AhatCamera>(*calibration);
  return opened;
}

}  // namespace tofnav

namespace tofnav {

std::optional<std::string> LossyDepthReason(const AhatRecording& recording) {
  const auto* hl2ss = dynamic_cast<const Hl2ssRecording*>(&recording);
  if (hl2ss == nullptr || hl2ss->config().profile_z != Hl2ssDepthProfile::kSame ||
      hl2ss->config().profile_ab == Hl2ssVideoProfile::kRaw) {
    return std::nullopt;
  }
  return "its depth is " + Hl2ssProfileName(hl2ss->config()) +
         ": 4 mm steps with codec noise, wrapping to 0-28 mm above 1023 mm (docs/ahat.md 3.6.5); "
         "record ZDEPTH+H265 for this stage (exact depth at 201-749 mm, a few Mbit/s)";
}

void RefuseLossyDepth(const AhatRecording& recording, const std::filesystem::path& path,
                      bool allow) {
  if (allow) return;
  if (const std::optional<std::string> reason = LossyDepthReason(recording)) {
    throw std::runtime_error(path.string() + ": " + *reason +
                             ", or pass --allow-lossy-depth to use it anyway");
  }
}

}  // namespace tofnav
