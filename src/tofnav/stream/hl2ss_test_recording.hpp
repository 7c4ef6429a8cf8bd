// SPDX-License-Identifier: BSD-3-Clause
// Test-only: a small synthetic hl2ss AHAT recording and calibration folder, for the live tests.
#pragma once

#include <cstdint>
#include <filesystem>

#include "tofnav/io/io_test_helpers.hpp"
#include "tofnav/recording/hl2ss_calibration.hpp"
#include "tofnav/recording/hl2ss_recording.hpp"

namespace tofnav::testing {

/// Frame `index` of the test recording: 45 Hz time stamps, patterned range and AB, a head pose
/// except in frame 2 (the locator failed).
inline AhatFrame Hl2ssTestFrame(int index) {
  AhatFrame f;
  f.host_ticks = 1'000'000 + 222'222 * static_cast<std::uint64_t>(index);
  f.sensor_ticks_ns = 5'000'000'000ULL + 22'222'222ULL * static_cast<std::uint64_t>(index);
  f.range_mm = Image<std::uint16_t>(kAhatWidth, kAhatHeight);
  f.ab = Image<std::uint16_t>(kAhatWidth, kAhatHeight);
  for (int v = 0; v < kAhatHeight; ++v) {
    for (int u = 0; u < kAhatWidth; ++u) {
      f.range_mm(u, v) = static_cast<std::uint16_t>(300 + (u + 2 * v + 7 * index) % 400);
      f.ab(u, v) = static_cast<std::uint16_t>((u * 31 + v * 17 + index) % 5000);
    }
  }
  if (index != 2) {
    f.world_from_rig =
        Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(0.1 * index, Eigen::Vector3d::UnitY())),
                {10.0 * index, 1600.0, -250.0});
  }
  return f;
}

/// The configuration a client sends for `profile` (RAW AB, as tofnav navigate asks).
inline Hl2ssAhatConfig Hl2ssTestConfig(Hl2ssDepthProfile profile, std::uint8_t mode = 1) {
  Hl2ssAhatConfig c;
  c.mode = mode;
  c.profile_z = profile;
  c.bitrate_bps = Hl2ssDefaultAhatBitrate(profile, Hl2ssVideoProfile::kRaw);
  c.encoder_options = {{10, 1}};
  return c;
}

/// `frames` frames in rm_depth_ahat.bin and a synthetic calibration, in a temporary folder.
struct Hl2ssTestRecording {
  TempDir dir;
  std::filesystem::path recording = dir.path() / "rm_depth_ahat.bin";
  AhatCalibration calibration = MakeSyntheticAhatCalibration();

  Hl2ssTestRecording(const std::string& tag, Hl2ssDepthProfile profile, int frames) : dir(tag) {
    Hl2ssRecordingWriter writer(recording, {.profile_z = profile});
    for (int i = 0; i < frames; ++i) writer.Append(Hl2ssTestFrame(i));
    writer.Close();
    WriteHl2ssCalibration(dir.path(), calibration);
  }
};

}  // namespace tofnav::testing
