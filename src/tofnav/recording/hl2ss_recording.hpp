// SPDX-License-Identifier: BSD-3-Clause
// hl2ss AHAT recordings (`HL2SSV23` .bin files, docs/ahat.md section 3): indexed reader and writer.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "tofnav/io/file.hpp"
#include "tofnav/recording/zdepth.hpp"
#include "tofnav/sensor/ahat_recording.hpp"

namespace tofnav {

enum class Hl2ssDepthProfile : std::uint8_t { kSame = 0, kZdepth = 1 };
enum class Hl2ssVideoProfile : std::uint8_t {
  kH264Base = 0,
  kH264Main = 1,
  kH264High = 2,
  kH265Main = 3,
  kRaw = 255,
};
/// Payload variants written by different hl2ss server versions (docs/ahat.md section 3.4).
enum class Hl2ssPayloadLayout : std::uint8_t {
  kCurrent,       // [size_z][size_ab][z][ab][sensor_ticks], server >= v1.0.33
  kSizedNoTicks,  // [size_z][size_ab][z][ab], v1.0.30-32 and older ZDEPTH
  kLegacySame,    // the whole payload is the AB blob, SAME mode <= v1.0.29
};

struct Hl2ssEncoderOption {
  std::uint64_t key = 0;
  std::uint64_t value = 0;
  bool operator==(const Hl2ssEncoderOption&) const = default;
};

/// The AHAT stream configuration stored after the file header (docs/ahat.md section 3.2).
struct Hl2ssAhatConfig {
  std::uint8_t mode = 1;  // 0 frames, 1 frames + rig pose
  std::uint8_t divisor = 1;
  Hl2ssDepthProfile profile_z = Hl2ssDepthProfile::kSame;
  Hl2ssVideoProfile profile_ab = Hl2ssVideoProfile::kRaw;
  std::uint8_t level = 255;  // H26x level code, 255 = default
  std::uint32_t bitrate_bps = 0;
  std::vector<Hl2ssEncoderOption> encoder_options;
  bool operator==(const Hl2ssAhatConfig&) const = default;
};

/// The hl2ss client's default bitrate: 512 * 512 * 45 * 12 * f, f = 1/75 (H264), 1/150 (H265)
/// or 1 (RAW), times 16 in SAME mode.
std::uint32_t Hl2ssDefaultAhatBitrate(Hl2ssDepthProfile profile_z, Hl2ssVideoProfile profile_ab);

/// An hl2ss AHAT recording. Opening reads only the header and the packet headers (a RAW file is
/// 1 MiB per frame); frames are decoded on demand. Packets with an empty AB blob are skipped
/// (as hl2ss clients do) and a truncated last packet is dropped; both are counted.
/// Range >= 4090 is set to 0 whatever the server version. Poses are world_from_rig [mm].
class Hl2ssRecording : public AhatRecording {
 public:
  explicit Hl2ssRecording(const std::filesystem::path& path);
  /// The same over a file held in memory; `source` names it in errors (fuzzing, live replay).
  Hl2ssRecording(std::vector<std::uint8_t> bytes, std::filesystem::path source);

  /// "hl2ss SAME+RAW", "hl2ss ZDEPTH+RAW", "hl2ss SAME+H265_MAIN", ...
  std::string format() const override;
  std::size_t frame_count() const override { return index_.size(); }
  std::uint64_t host_ticks(std::size_t index) const override;
  /// RAW and ZDEPTH+RAW; H26x profiles throw IoError (libavcodec support is not built).
  /// ZDEPTH range is exact at 201..749 mm and in 2 mm steps above, so depth_step_mm = 2.
  AhatFrame ReadFrame(std::size_t index) const override;
  std::optional<AhatCalibration> calibration() const override { return std::nullopt; }

  const Hl2ssAhatConfig& config() const { return config_; }
  const std::vector<std::uint8_t>& user_data() const { return user_data_; }
  Hl2ssPayloadLayout layout(std::size_t index) const;
  /// Byte offset of frame `index`'s packet (its timestamp field).
  std::uint64_t packet_offset(std::size_t index) const;
  std::size_t skipped_empty_packets() const { return skipped_empty_; }
  /// True when the file ends inside a packet (recording killed); that packet is not a frame.
  bool truncated_tail() const { return truncated_tail_; }

 private:
  struct Packet {
    std::uint64_t offset = 0;  // of the timestamp field
    std::uint64_t timestamp = 0;
    std::uint32_t payload_size = 0;
    std::uint32_t size_z = 0;
    Hl2ssPayloadLayout layout = Hl2ssPayloadLayout::kCurrent;
  };

  void ReadAt(std::uint64_t offset, std::span<std::uint8_t> out, const char* what) const;
  void Open();
  void ReadHeader();
  void IndexPackets(std::uint64_t first_packet);
  const Packet& At(std::size_t index) const;

  std::filesystem::path path_;
  std::optional<RandomAccessFile> file_;
  std::vector<std::uint8_t> memory_;
  std::uint64_t size_ = 0;
  Hl2ssAhatConfig config_;
  std::vector<std::uint8_t> user_data_;
  std::uint64_t header_end_ = 0;
  std::vector<Packet> index_;
  std::size_t skipped_empty_ = 0;
  bool truncated_tail_ = false;
};

/// Opens an hl2ss AHAT recording; IoError when it is not one.
std::unique_ptr<Hl2ssRecording> OpenHl2ssRecording(const std::filesystem::path& path);

struct Hl2ssWriterOptions {
  std::uint8_t mode = 1;  // 1 stores world_from_rig per frame, 0 does not
  std::uint8_t divisor = 1;
  Hl2ssDepthProfile profile_z = Hl2ssDepthProfile::kSame;
  Hl2ssVideoProfile profile_ab = Hl2ssVideoProfile::kRaw;  // only RAW can be written
  std::uint8_t level = 255;
  std::optional<std::uint32_t> bitrate_bps;  // nullopt: Hl2ssDefaultAhatBitrate
  /// Key 10 = GOP size; the hl2ss client sends 1 for RAW.
  std::vector<Hl2ssEncoderOption> encoder_options = {{10, 1}};
  std::string user = "created by tofnav";
  ZdepthEncodeOptions zdepth;  // ZDEPTH only
  void Check() const;
};

/// Writes an hl2ss AHAT recording in the current payload layout (server >= v1.0.33), byte
/// compatible with hl2ss_io. Atomic: the file appears only on Close(); destroyed without
/// Close() it leaves nothing behind.
class Hl2ssRecordingWriter {
 public:
  Hl2ssRecordingWriter(const std::filesystem::path& path, const Hl2ssWriterOptions& options = {});

  /// Appends a 512 x 512 frame; host_ticks must not decrease. Range >= 4090 is written as 0 (as
  /// the server does); a missing sensor_ticks_ns as 0; a missing pose as 16 zeros (mode 1).
  void Append(const AhatFrame& frame);
  void Close();
  std::size_t frames_written() const { return frames_; }

 private:
  AtomicFileWriter file_;
  Hl2ssWriterOptions options_;
  std::size_t frames_ = 0;
  std::uint64_t last_ticks_ = 0;
  bool closed_ = false;
};

}  // namespace tofnav
