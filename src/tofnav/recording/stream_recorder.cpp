// SPDX-License-Identifier: BSD-3-Clause
// StreamRecorder capture folders (docs/ahat.md section 7): reader and streaming writer.
#include "tofnav/recording/stream_recorder.hpp"

#include <algorithm>
#include <charconv>
#include <string_view>
#include <system_error>

#include "tofnav/core/require.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/recording/pgm.hpp"
#include "tofnav/recording/stream_recorder_files.hpp"

namespace tofnav {
namespace {

/// A 512 x 512 16-bit PGM is 524 305 B with the recorder's header; anything much larger is not
/// an AHAT frame and is refused before allocating.
constexpr std::uint64_t kMaxPgmEntryBytes = 1 << 20;
/// FILETIME of the Unix epoch (100 ns ticks since 1601-01-01), docs/ahat.md section 7.6.
constexpr std::uint64_t kUnixEpochFiletime = 116444736000000000ULL;
constexpr std::uint64_t kFiletimeTicksPerSecond = 10000000ULL;

struct FrameName {
  std::uint64_t filetime = 0;
  bool ab = false;
};

// `^[0-9]+(_ab)?\.pgm$` -> timestamp and kind; nullopt for any other name. IoError when the
// digits do not fit 64 bits.
std::optional<FrameName> ParseFrameName(const TarEntry& entry, const std::filesystem::path& tar) {
  std::string_view name = entry.name;
  constexpr std::string_view kPgm = ".pgm";
  constexpr std::string_view kAb = "_ab";
  if (name.size() <= kPgm.size() || !name.ends_with(kPgm)) return std::nullopt;
  name.remove_suffix(kPgm.size());
  FrameName parsed;
  if (name.ends_with(kAb)) {
    parsed.ab = true;
    name.remove_suffix(kAb.size());
  }
  if (name.empty() ||
      !std::all_of(name.begin(), name.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    return std::nullopt;
  }
  const auto [end, error] =
      std::from_chars(name.data(), name.data() + name.size(), parsed.filetime);
  if (error != std::errc{} || end != name.data() + name.size()) {
    throw IoError(tar, entry.header_offset,
                  "timestamp of tar entry '" + entry.name + "' does not fit 64 bits");
  }
  return parsed;
}

// The LUT after checking its size, so a wrong file is never read whole.
Image<Eigen::Vector2f> ReadLut(const std::filesystem::path& path) {
  const RandomAccessFile file(path);
  if (file.size() != kStreamRecorderLutBytes) {
    throw IoError(path, std::min(file.size(), kStreamRecorderLutBytes),
                  "expected " + std::to_string(kStreamRecorderLutBytes) +
                      " bytes (512 x 512 x 3 float32), found " + std::to_string(file.size()));
  }
  return DecodeStreamRecorderLut(file.ReadAt(0, kStreamRecorderLutBytes, "LUT"), path);
}

std::string ReadText(const std::filesystem::path& path) {
  const std::vector<std::uint8_t> bytes = ReadFileBytes(path);
  return {bytes.begin(), bytes.end()};
}

Image<std::uint16_t> ReadPgmEntry(const RandomAccessFile& tar, const TarEntry& entry) {
  if (entry.size > kMaxPgmEntryBytes) {
    throw IoError(tar.path(), entry.data_offset,
                  "tar entry '" + entry.name + "' has " + std::to_string(entry.size) +
                      " bytes, too many for a 512 x 512 16-bit PGM");
  }
  const std::vector<std::uint8_t> bytes =
      tar.ReadAt(entry.data_offset, static_cast<std::size_t>(entry.size), "PGM entry");
  Image<std::uint16_t> image = DecodePgm16(bytes, tar.path(), entry.data_offset);
  if (image.width() != kAhatWidth || image.height() != kAhatHeight) {
    throw IoError(tar.path(), entry.data_offset,
                  "expected a 512 x 512 PGM in tar entry '" + entry.name + "', found " +
                      std::to_string(image.width()) + " x " + std::to_string(image.height()));
  }
  return image;
}

std::filesystem::path CreateFolder(const std::filesystem::path& folder) {
  std::error_code error;
  std::filesystem::create_directories(folder, error);
  if (error) throw IoError(folder, std::nullopt, "cannot create the folder: " + error.message());
  return folder;
}

const AhatCalibration& CheckedCalibration(const AhatCalibration& calibration) {
  Require(calibration.uv2xy.width() == kAhatWidth && calibration.uv2xy.height() == kAhatHeight,
          "StreamRecorder needs a 512 x 512 uv2xy table");
  Require(calibration.sample_offset_px == 0.5,
          "the StreamRecorder LUT is sampled at (u + 0.5, v + 0.5): sample_offset_px must be 0.5");
  return calibration;
}

}  // namespace

std::unique_ptr<StreamRecorderCapture> StreamRecorderCapture::Open(
    const std::filesystem::path& folder) {
  std::unique_ptr<StreamRecorderCapture> capture(
      new StreamRecorderCapture(RandomAccessFile(folder / kStreamRecorderTar)));
  capture->tar_index_ = IndexTar(capture->tar_);

  // Pair `<ts>.pgm` and `<ts>_ab.pgm` by timestamp; the map also sorts the frames.
  struct Pending {
    std::optional<TarEntry> range;
    std::optional<TarEntry> ab;
  };
  std::map<std::uint64_t, Pending> pending;
  for (const TarEntry& entry : capture->tar_index_.entries) {
    const std::optional<FrameName> name = ParseFrameName(entry, capture->tar_.path());
    if (!name) {
      ++capture->report_.other_entries;
      continue;
    }
    std::optional<TarEntry>& slot =
        name->ab ? pending[name->filetime].ab : pending[name->filetime].range;
    if (slot) {
      throw IoError(capture->tar_.path(), entry.header_offset,
                    "duplicate tar entry '" + entry.name + "'");
    }
    slot = entry;
  }
  for (auto& [filetime, entries] : pending) {
    if (entries.range && entries.ab) {
      capture->frames_.push_back({filetime, std::move(*entries.range), std::move(*entries.ab)});
    } else {
      ++capture->report_.unpaired_frames;
    }
  }

  const std::filesystem::path lut_path = folder / kStreamRecorderLut;
  capture->calibration_.uv2xy = ReadLut(lut_path);
  capture->calibration_.sample_offset_px = 0.5;  // the recorder samples (u + 0.5, v + 0.5)
  const std::filesystem::path extrinsics_path = folder / kStreamRecorderExtrinsics;
  capture->calibration_.rig_from_ahat =
      ParseStreamRecorderExtrinsics(ReadText(extrinsics_path), extrinsics_path);

  const std::filesystem::path rig2world_path = folder / kStreamRecorderRig2World;
  if (std::filesystem::exists(rig2world_path)) {  // optional: absent when nothing was located
    capture->world_from_rig_ =
        ParseStreamRecorderRig2World(ReadText(rig2world_path), rig2world_path);
  }
  for (const Frame& frame : capture->frames_) {
    if (!capture->world_from_rig_.contains(frame.filetime)) ++capture->report_.unposed_frames;
  }
  return capture;
}

std::uint64_t StreamRecorderCapture::host_ticks(std::size_t index) const {
  Require(index < frames_.size(), "frame index out of range");
  return frames_[index].filetime;
}

AhatFrame StreamRecorderCapture::ReadFrame(std::size_t index) const {
  Require(index < frames_.size(), "frame index out of range");
  const Frame& entries = frames_[index];
  AhatFrame frame;
  frame.host_ticks = entries.filetime;
  frame.range_mm = ReadPgmEntry(tar_, entries.range);
  for (std::uint16_t& range_mm : frame.range_mm.pixels()) {
    if (range_mm >= kAhatInvalidRange) range_mm = 0;  // the recorder already does; be sure
  }
  frame.ab = ReadPgmEntry(tar_, entries.ab);
  const auto pose = world_from_rig_.find(entries.filetime);  // exact timestamp join
  if (pose != world_from_rig_.end()) frame.world_from_rig = pose->second;
  return frame;
}

StreamRecorderWriter::StreamRecorderWriter(const std::filesystem::path& folder,
                                           const AhatCalibration& calibration)
    : calibration_(CheckedCalibration(calibration)),
      folder_(CreateFolder(folder)),
      tar_(folder_ / kStreamRecorderTar),
      rig2world_(folder_ / kStreamRecorderRig2World) {}

void StreamRecorderWriter::Append(const AhatFrame& frame) {
  Require(!closed_, "StreamRecorderWriter::Append after Close");
  Require(frame.range_mm.width() == kAhatWidth && frame.range_mm.height() == kAhatHeight &&
              frame.ab.width() == kAhatWidth && frame.ab.height() == kAhatHeight,
          "StreamRecorder frames need 512 x 512 range and AB images");
  Require(!last_ticks_ || frame.host_ticks > *last_ticks_,
          "StreamRecorder timestamps must increase strictly");
  last_ticks_ = frame.host_ticks;
  // The recorder stamps each tar entry with the wall clock; derive it from the FILETIME.
  const std::uint64_t mtime_s =
      frame.host_ticks > kUnixEpochFiletime
          ? (frame.host_ticks - kUnixEpochFiletime) / kFiletimeTicksPerSecond
          : 0;
  const std::string stem = std::to_string(frame.host_ticks);
  tar_.Add(stem + "_ab.pgm", EncodePgm16(frame.ab), mtime_s);  // the recorder's order
  tar_.Add(stem + ".pgm", EncodePgm16(frame.range_mm), mtime_s);
  if (frame.world_from_rig) {
    rig2world_.Write(FormatStreamRecorderRig2WorldLine(frame.host_ticks, *frame.world_from_rig));
  }
}

void StreamRecorderWriter::Close() {
  Require(!closed_, "StreamRecorderWriter::Close called twice");
  WriteFileAtomically(folder_ / kStreamRecorderLut, EncodeStreamRecorderLut(calibration_.uv2xy));
  WriteFileAtomically(folder_ / kStreamRecorderExtrinsics,
                      FormatStreamRecorderExtrinsics(calibration_.rig_from_ahat));
  rig2world_.Commit();
  tar_.Close();
  closed_ = true;
}

}  // namespace tofnav
