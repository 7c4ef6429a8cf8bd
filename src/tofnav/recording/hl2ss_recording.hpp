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
#include "tofnav/recording/h26x_codec.hpp"
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

/// A stream profile as users name it: "zdepth+h265", "same+h264", "same+raw", ... ("raw" and
/// "zdepth" are same+raw and zdepth+raw; "h264" is H.264 Main, "h264-base" and "h264-high" the
/// others). nullopt for anything else.
struct Hl2ssStreamProfile {
  Hl2ssDepthProfile profile_z = Hl2ssDepthProfile::kZdepth;
  Hl2ssVideoProfile profile_ab = Hl2ssVideoProfile::kH265Main;
  bool operator==(const Hl2ssStreamProfile&) const = default;
};
std::optional<Hl2ssStreamProfile> ParseHl2ssStreamProfile(const std::string& text);
/// The canonical name of a profile: "zdepth+h265", "same+h264-base", ..., and "raw" / "zdepth"
/// for the RAW-AB profiles.
std::string Hl2ssStreamProfileName(const Hl2ssStreamProfile& profile);
/// Every profile's canonical name, for help texts.
std::string Hl2ssStreamProfileChoices();

/// The codec of an H26x AB profile (H.265 for H265_MAIN, H.264 for the others; RAW has none and
/// gives H.264, never used).
H26xCodec Hl2ssVideoCodec(Hl2ssVideoProfile profile_ab);

/// The hl2ss client's default encoder options: GOP (key 10) 45 frames for H26x, 1 for RAW.
std::vector<Hl2ssEncoderOption> Hl2ssDefaultEncoderOptions(Hl2ssVideoProfile profile_ab);
/// The GOP a configuration asks for (option key 10; the default when absent).
int Hl2ssGopFrames(const Hl2ssAhatConfig& config);
/// The encoder settings that stand in for the headset's for `config` (codec, H.264 profile,
/// bitrate, GOP, frame rate); PreconditionError for RAW.
H26xEncoderOptions Hl2ssEncoderSettings(const Hl2ssAhatConfig& config);

/// Decodes the H.264/H.265 packets of one hl2ss AHAT stream in order, as hl2ss's clients do
/// (docs/ahat.md 3.6): SAME gives range = 4 Y (4 mm steps, wrapping above 1023 mm) and
/// half-resolution AB; ZDEPTH gives the Zdepth range and full-resolution AB = Y^2. Shared by the
/// recording reader and the live client.
class Hl2ssVideoDecoder {
 public:
  /// `frame_threads` > 1: pictures come out of ReceivePicture up to that many units late (a
  /// recording read ahead; H26xDecoder).
  explicit Hl2ssVideoDecoder(const Hl2ssAhatConfig& config, int frame_threads = 1);
  /// Decodes one unit into the picture FillFrame reads, at once (one frame thread only).
  void Decode(std::span<const std::uint8_t> access_unit, const H26xUnitPlace& place);
  /// Read ahead: send units, receive their pictures oldest first (false: not out yet). Then
  /// FillFrame: range, AB and the precision flags of the picture received last, with its packet's
  /// Zdepth blob (empty for SAME; it starts at byte `zdepth_offset` of `source`).
  void Send(std::span<const std::uint8_t> access_unit, const H26xUnitPlace& place) {
    decoder_.Send(access_unit, place);
  }
  void SendEnd() { decoder_.SendEnd(); }
  bool ReceivePicture() { return decoder_.Receive(picture_); }
  std::size_t in_flight() const { return decoder_.in_flight(); }
  void FillFrame(std::span<const std::uint8_t> zdepth, std::uint64_t zdepth_offset,
                 const std::filesystem::path& source, AhatFrame& frame) const;
  /// After an error or a seek: the next unit must be a key frame.
  void Reset() { decoder_.Reset(); }
  H26xCodec codec() const { return decoder_.codec(); }

 private:
  Hl2ssDepthProfile profile_z_;
  H26xDecoder decoder_;
  Yuv420Picture picture_;  // the last picture received, reused: no allocation per frame
};

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
  /// Every profile. ZDEPTH range is exact at 201..749 mm and in 2 mm steps above, so
  /// depth_step_mm = 2; SAME + H26x range has 4 mm steps. H26x frames are decoded from the key
  /// frame at or before `index` (or on from the last frame read: reading in order decodes each
  /// unit once).
  AhatFrame ReadFrame(std::size_t index) const override;
  std::optional<AhatCalibration> calibration() const override { return std::nullopt; }
  /// H26x only: decodes frame `index` with `video`, which must have decoded the frames since the
  /// last key frame (the live client's decoder, fed one packet at a time).
  AhatFrame ReadFrameWith(std::size_t index, Hl2ssVideoDecoder& video) const;

  const Hl2ssAhatConfig& config() const { return config_; }
  const std::vector<std::uint8_t>& user_data() const { return user_data_; }
  Hl2ssPayloadLayout layout(std::size_t index) const;
  /// Byte offset of frame `index`'s packet (its timestamp field).
  std::uint64_t packet_offset(std::size_t index) const;
  std::size_t skipped_empty_packets() const { return skipped_empty_; }
  /// H26x only: whether frame `index`'s access unit is a key frame (IDR), and the key frames'
  /// spacing (0 for RAW or a single key frame).
  bool key_frame(std::size_t index) const { return At(index).key; }
  int measured_gop_frames() const;
  /// Bits per second of the AB (or ZAB) blobs and of the Zdepth blobs over the recording's
  /// duration (0 with fewer than two frames).
  double ab_bitrate_bps() const;
  double zdepth_bitrate_bps() const;
  /// Mean bytes of the AB (or ZAB) and Zdepth blobs per frame (0 without frames).
  double payload_bytes_per_frame() const;
  /// True when the file ends inside a packet (recording killed); that packet is not a frame.
  bool truncated_tail() const { return truncated_tail_; }

 private:
  struct Packet {
    std::uint64_t offset = 0;  // of the timestamp field
    std::uint64_t timestamp = 0;
    std::uint32_t payload_size = 0;
    std::uint32_t size_z = 0;
    std::uint32_t size_ab = 0;
    Hl2ssPayloadLayout layout = Hl2ssPayloadLayout::kCurrent;
    bool key = false;  // H26x: the unit holds an IDR picture
  };

  void ReadAt(std::uint64_t offset, std::span<std::uint8_t> out, const char* what) const;
  void Open();
  void ReadHeader();
  void IndexPackets(std::uint64_t first_packet);
  const Packet& At(std::size_t index) const;
  std::uint64_t AbBlobOffset(const Packet& packet) const;
  std::uint64_t BlobBytes(std::uint32_t Packet::*size) const;  // summed over the frames
  void ReadTail(const Packet& packet, std::uint64_t cursor, AhatFrame& frame) const;
  AhatFrame ReadVideoFrame(std::size_t index) const;
  // Frame `index` from the picture `video` received last: its Zdepth blob, the invalid range
  // zeroed, the packet's tail.
  AhatFrame VideoFrameOf(std::size_t index, const Hl2ssVideoDecoder& video) const;

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
  // H26x: the decoder and the index of the frame it decodes next (kNone: it must be reset).
  static constexpr std::size_t kNone = static_cast<std::size_t>(-1);
  mutable std::unique_ptr<Hl2ssVideoDecoder> video_;  // reads ahead (kReadAheadThreads)
  mutable std::size_t next_video_frame_ = kNone;      // the next picture video_ gives
  mutable std::size_t next_video_unit_ = kNone;       // the next unit to send it
};

/// Opens an hl2ss AHAT recording; IoError when it is not one.
std::unique_ptr<Hl2ssRecording> OpenHl2ssRecording(const std::filesystem::path& path);

struct Hl2ssWriterOptions {
  std::uint8_t mode = 1;  // 1 stores world_from_rig per frame, 0 does not
  std::uint8_t divisor = 1;
  Hl2ssDepthProfile profile_z = Hl2ssDepthProfile::kSame;
  /// RAW, or H.264 / H.265 encoded with libx264 / libx265 as the headset would
  /// (Hl2ssEncoderSettings).
  Hl2ssVideoProfile profile_ab = Hl2ssVideoProfile::kRaw;
  std::uint8_t level = 255;
  std::optional<std::uint32_t> bitrate_bps;  // nullopt: Hl2ssDefaultAhatBitrate
  /// Key 10 = GOP size; nullopt: the hl2ss client's (Hl2ssDefaultEncoderOptions).
  std::optional<std::vector<Hl2ssEncoderOption>> encoder_options;
  std::string user = "created by tofnav";
  ZdepthEncodeOptions zdepth;  // ZDEPTH only
  void Check() const;
  /// The configuration stored in the file (defaults filled in).
  Hl2ssAhatConfig Config() const;
};

/// Encodes frames into hl2ss AHAT packets (docs/ahat.md 3.3), as the server sends them for
/// `config` and a recording stores them: header, payload (Zdepth blob, RAW planes or one
/// H.264/H.265 unit), sensor ticks, and the pose in mode 1. H26x streams start with a key frame,
/// as each connection of the headset does.
class Hl2ssPacketEncoder {
 public:
  explicit Hl2ssPacketEncoder(const Hl2ssAhatConfig& config,
                              const ZdepthEncodeOptions& zdepth = {});
  ~Hl2ssPacketEncoder();
  Hl2ssPacketEncoder(const Hl2ssPacketEncoder&) = delete;
  Hl2ssPacketEncoder& operator=(const Hl2ssPacketEncoder&) = delete;

  /// The next frame's packet. Range >= 4090 is sent as 0; a missing sensor_ticks_ns as 0; a
  /// missing pose as 16 zeros (mode 1).
  std::vector<std::uint8_t> Encode(const AhatFrame& frame);
  /// Bytes of the last packet's AB (or ZAB) blob.
  std::uint64_t last_ab_blob_bytes() const { return last_ab_blob_bytes_; }

 private:
  Hl2ssAhatConfig config_;
  ZdepthEncodeOptions zdepth_;
  std::unique_ptr<H26xEncoder> video_;
  std::uint64_t last_ab_blob_bytes_ = 0;
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
  /// Bytes of the AB (or ZAB) blobs written so far (the encoded stream for H26x).
  std::uint64_t ab_blob_bytes() const { return video_bytes_; }

 private:
  AtomicFileWriter file_;
  Hl2ssWriterOptions options_;
  Hl2ssPacketEncoder packets_;
  std::uint64_t video_bytes_ = 0;
  std::size_t frames_ = 0;
  std::uint64_t last_ticks_ = 0;
  bool closed_ = false;
};

}  // namespace tofnav
