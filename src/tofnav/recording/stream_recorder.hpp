// SPDX-License-Identifier: BSD-3-Clause
// StreamRecorder (microsoft/HoloLens2ForCV) AHAT capture folders: reader and streaming writer.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "tofnav/io/file.hpp"
#include "tofnav/io/tar.hpp"
#include "tofnav/sensor/ahat_recording.hpp"

namespace tofnav {

/// File names inside a capture folder (the sensor's friendly name is "Depth AHaT").
inline constexpr const char* kStreamRecorderTar = "Depth AHaT.tar";
inline constexpr const char* kStreamRecorderLut = "Depth AHaT_lut.bin";
inline constexpr const char* kStreamRecorderExtrinsics = "Depth AHaT_extrinsics.txt";
inline constexpr const char* kStreamRecorderRig2World = "Depth AHaT_rig2world.txt";

/// What indexing skipped; none of it is an error.
struct StreamRecorderReport {
  std::size_t unpaired_frames = 0;  // a `<ts>.pgm` without `<ts>_ab.pgm` or vice versa
  std::size_t other_entries = 0;    // tar names not matching ^[0-9]+(_ab)?\.pgm$
  std::size_t unposed_frames = 0;   // frames without a rig2world line (not located)
};

/// A capture folder: `Depth AHaT.tar` (per frame `<ts>.pgm` range and `<ts>_ab.pgm` AB),
/// `Depth AHaT_lut.bin` and `Depth AHaT_extrinsics.txt` (required), `Depth AHaT_rig2world.txt`
/// (optional). Timestamps `<ts>` are FILETIME: 100 ns ticks since 1601-01-01 UTC (not QPC);
/// host_ticks() returns them unchanged. Frames are sorted by timestamp; poses join by exact
/// timestamp. Device metres become mm here.
class StreamRecorderCapture : public AhatRecording {
 public:
  /// Indexes the folder (tar headers, LUT, text files; PGMs are decoded by ReadFrame). IoError
  /// naming the file (and the byte offset) when a required file is missing, any file is
  /// malformed, or the tar holds the same `<ts>.pgm` or `<ts>_ab.pgm` twice.
  static std::unique_ptr<StreamRecorderCapture> Open(const std::filesystem::path& folder);

  std::string format() const override { return "StreamRecorder"; }
  std::size_t frame_count() const override { return frames_.size(); }
  /// FILETIME of frame `index` (100 ns since 1601-01-01 UTC).
  std::uint64_t host_ticks(std::size_t index) const override;
  /// Range (codes >= 4090 -> 0) and AB, both 512 x 512, plus world_from_rig [mm] when located.
  AhatFrame ReadFrame(std::size_t index) const override;
  /// uv2xy = (x / z, y / z) of the LUT's unit rays (NaN where z <= 0 or not finite), s = 0.5,
  /// rig_from_ahat = inverse of the stored rig -> camera extrinsics [mm].
  std::optional<AhatCalibration> calibration() const override { return calibration_; }

  std::size_t unpaired_frames() const { return report_.unpaired_frames; }
  const StreamRecorderReport& report() const { return report_; }
  /// How the tar ended (a killed recorder leaves no end blocks or a cut last entry).
  const TarIndex& tar_index() const { return tar_index_; }

 private:
  struct Frame {
    std::uint64_t filetime = 0;
    TarEntry range;
    TarEntry ab;
  };
  explicit StreamRecorderCapture(RandomAccessFile tar) : tar_(std::move(tar)) {}

  RandomAccessFile tar_;
  TarIndex tar_index_;
  std::vector<Frame> frames_;
  std::map<std::uint64_t, Rigid3d> world_from_rig_;  // by FILETIME
  AhatCalibration calibration_;
  StreamRecorderReport report_;
};

/// Writes a capture folder frame by frame, in the recorder's layout: the tar streams through an
/// AtomicFileWriter, and Close() writes the LUT, extrinsics and rig2world files and renames
/// everything into place. Text matrices use 9 significant digits (the recorder writes 6), which
/// reproduces float-stored values exactly and keeps round trips near double precision.
class StreamRecorderWriter {
 public:
  /// Creates `folder` if needed. PreconditionError unless `calibration` has a 512 x 512 uv2xy
  /// sampled at s = 0.5 (the LUT's definition).
  StreamRecorderWriter(const std::filesystem::path& folder, const AhatCalibration& calibration);

  /// Appends `<ts>_ab.pgm` then `<ts>.pgm` with ts = frame.host_ticks (FILETIME), and a rig2world
  /// line when the frame has world_from_rig. PreconditionError unless both images are 512 x 512
  /// and host_ticks increase strictly. Ranges are written as given (0 = invalid).
  void Append(const AhatFrame& frame);
  /// Finishes all files; without Close() nothing is left under the final names.
  void Close();

 private:
  AhatCalibration calibration_;  // validated first, before anything is created
  std::filesystem::path folder_;
  TarWriter tar_;
  AtomicFileWriter rig2world_;
  std::optional<std::uint64_t> last_ticks_;
  bool closed_ = false;
};

}  // namespace tofnav
