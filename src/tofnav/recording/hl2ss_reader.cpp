// SPDX-License-Identifier: BSD-3-Clause
// hl2ss AHAT recording reader: header, packet index, per-packet layout detection, frame decoding.
#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <optional>
#include <utility>

#include "tofnav/core/require.hpp"
#include "tofnav/io/binary.hpp"
#include "tofnav/recording/hl2ss_format.hpp"
#include "tofnav/recording/hl2ss_matrix.hpp"
#include "tofnav/recording/hl2ss_recording.hpp"

namespace tofnav {
namespace {

static_assert(std::endian::native == std::endian::little, "RAW planes are copied as stored (LE)");

std::string Printable(std::span<const std::uint8_t> bytes) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string text;
  for (const std::uint8_t byte : bytes) {
    if (byte >= 0x20 && byte < 0x7F) {
      text += static_cast<char>(byte);
    } else {
      text += std::string("\\x") + kHex[byte >> 4] + kHex[byte & 15];
    }
  }
  return text;
}

std::span<std::uint8_t> AsBytes(Image<std::uint16_t>& image) {
  return {reinterpret_cast<std::uint8_t*>(image.data()), image.size() * sizeof(std::uint16_t)};
}

/// d >= 4090 -> 0 (docs/ahat.md section 1); branch-free so it vectorises.
void ZeroInvalidRange(Image<std::uint16_t>& range_mm) {
  std::uint16_t* pixels = range_mm.data();
  const std::size_t count = range_mm.size();
  for (std::size_t i = 0; i < count; ++i) {
    pixels[i] = static_cast<std::uint16_t>(pixels[i] < kAhatInvalidRange ? pixels[i] : 0);
  }
}

}  // namespace

Hl2ssRecording::Hl2ssRecording(const std::filesystem::path& path) : path_(path) {
  file_.emplace(path);
  size_ = file_->size();
  Open();
}

Hl2ssRecording::Hl2ssRecording(std::vector<std::uint8_t> bytes, std::filesystem::path source)
    : path_(std::move(source)), memory_(std::move(bytes)) {
  size_ = memory_.size();
  Open();
}

void Hl2ssRecording::Open() {
  ReadHeader();
  IndexPackets(header_end_);
}

void Hl2ssRecording::ReadAt(std::uint64_t offset, std::span<std::uint8_t> out,
                            const char* what) const {
  if (file_) return file_->ReadAt(offset, out, what);
  if (offset > size_ || out.size() > size_ - offset) {
    const std::uint64_t available = offset > size_ ? 0 : size_ - offset;
    throw IoError(path_, std::min(offset, size_) + available,
                  "expected " + std::to_string(out.size()) + " bytes of " + what +
                      ", the data ends after " + std::to_string(available));
  }
  if (!out.empty()) std::memcpy(out.data(), memory_.data() + offset, out.size());
}

void Hl2ssRecording::ReadHeader() {
  std::array<std::uint8_t, kHl2ssMagicBytes + 6> head;
  ReadAt(0, head, "HL2SSV23 header");
  const auto magic = std::span(head).first(kHl2ssMagicBytes);
  if (std::memcmp(magic.data(), kHl2ssMagic, kHl2ssMagicBytes) != 0) {
    const std::string found = Printable(magic);
    const bool older = found == "X38HL2SS" || found == "V02HL2SS";
    throw IoError(path_, 0,
                  "expected the magic \"HL2SSV23\", found \"" + found + "\"" +
                      (older ? " (an older hl2ss recording format, not supported)" : ""));
  }
  ByteReader reader(head, path_);
  reader.Skip(kHl2ssMagicBytes, "magic");
  const auto port = reader.Le<std::uint16_t>("port");
  if (port != kHl2ssAhatPort) {
    throw IoError(path_, kHl2ssMagicBytes,
                  "port " + std::to_string(port) + " is not the AHAT stream (3804)");
  }
  const auto user_bytes = reader.Le<std::uint32_t>("user_len");
  if (user_bytes > size_ - head.size()) {
    throw IoError(path_, kHl2ssMagicBytes + 2,
                  "user_len " + std::to_string(user_bytes) + " exceeds the " +
                      std::to_string(size_ - head.size()) + " bytes left in the file");
  }
  user_data_.resize(user_bytes);
  ReadAt(head.size(), user_data_, "user data");

  const std::uint64_t config_offset = head.size() + user_bytes;
  std::array<std::uint8_t, 10> fixed;
  ReadAt(config_offset, fixed, "AHAT config");
  ByteReader config(fixed, path_, config_offset);
  const auto field_error = [&](std::uint64_t field, const std::string& message) {
    return IoError(path_, config_offset + field, message);
  };
  config_.mode = config.Le<std::uint8_t>("mode");
  if (config_.mode > 1) {
    throw field_error(0, "mode must be 0 or 1, found " + std::to_string(config_.mode));
  }
  config_.divisor = config.Le<std::uint8_t>("divisor");
  const auto profile_z = config.Le<std::uint8_t>("profile_z");
  if (profile_z > 1) {
    throw field_error(2, "profile_z must be 0 or 1, found " + std::to_string(profile_z));
  }
  config_.profile_z = static_cast<Hl2ssDepthProfile>(profile_z);
  const auto profile_ab = config.Le<std::uint8_t>("profile_ab");
  if (profile_ab > 3 && profile_ab != 255) {
    throw field_error(3, "profile_ab must be 0..3 or 255, found " + std::to_string(profile_ab));
  }
  config_.profile_ab = static_cast<Hl2ssVideoProfile>(profile_ab);
  config_.level = config.Le<std::uint8_t>("level");
  config_.bitrate_bps = config.Le<std::uint32_t>("bitrate");
  const auto option_count = config.Le<std::uint8_t>("n_options");

  const std::uint64_t options_offset = config_offset + fixed.size();
  std::vector<std::uint8_t> option_bytes(std::size_t{16} * option_count);
  ReadAt(options_offset, option_bytes, "encoder options");
  ByteReader options(option_bytes, path_, options_offset);
  for (int i = 0; i < option_count; ++i) {
    const auto key = options.Le<std::uint64_t>("option key");
    config_.encoder_options.push_back({key, options.Le<std::uint64_t>("option value")});
  }
  header_end_ = options_offset + option_bytes.size();
}

void Hl2ssRecording::IndexPackets(std::uint64_t offset) {
  const std::uint64_t pose_bytes = config_.mode == 1 ? kHl2ssPoseBytes : 0;
  while (offset < size_) {
    const std::uint64_t available = size_ - offset;
    // The packet header and the first payload bytes (the size fields, when present).
    std::array<std::uint8_t, kHl2ssPacketHeaderBytes + kHl2ssSizeFieldsBytes> head{};
    const auto head_bytes =
        static_cast<std::size_t>(std::min<std::uint64_t>(available, head.size()));
    if (head_bytes < kHl2ssPacketHeaderBytes) {
      truncated_tail_ = true;
      return;
    }
    ReadAt(offset, std::span(head).first(head_bytes), "packet header");
    Packet packet;
    packet.offset = offset;
    std::memcpy(&packet.timestamp, head.data(), sizeof(packet.timestamp));
    std::memcpy(&packet.payload_size, head.data() + 8, sizeof(packet.payload_size));
    const std::size_t needed = std::min<std::size_t>(packet.payload_size, kHl2ssSizeFieldsBytes);
    if (head_bytes < kHl2ssPacketHeaderBytes + needed) {
      truncated_tail_ = true;  // ends before its size fields: nothing left to check
      return;
    }
    const Hl2ssPayloadSizes sizes = ClassifyHl2ssPayload(
        config_, packet.payload_size, std::span(head).subspan(kHl2ssPacketHeaderBytes, needed),
        path_, offset);
    packet.layout = sizes.layout;
    packet.size_z = sizes.size_z;
    packet.size_ab = sizes.size_ab;
    const std::uint64_t end = offset + kHl2ssPacketHeaderBytes + packet.payload_size + pose_bytes;
    if (end > size_) {
      truncated_tail_ = true;
      return;
    }
    if (sizes.size_ab == 0) {
      ++skipped_empty_;  // encoder hiccup; hl2ss clients drop these too
    } else {
      if (config_.profile_ab != Hl2ssVideoProfile::kRaw) {
        std::vector<std::uint8_t> unit(packet.size_ab);
        ReadAt(AbBlobOffset(packet), unit, "access unit");
        packet.key = H26xIsKeyFrame(Hl2ssVideoCodec(config_.profile_ab), unit);
      }
      if (!index_.empty() && packet.timestamp < index_.back().timestamp) {
        throw IoError(path_, offset,
                      "timestamp " + std::to_string(packet.timestamp) +
                          " is earlier than the previous frame's " +
                          std::to_string(index_.back().timestamp));
      }
      index_.push_back(packet);
    }
    offset = end;
  }
}

const Hl2ssRecording::Packet& Hl2ssRecording::At(std::size_t index) const {
  Require(index < index_.size(), "frame index out of range");
  return index_[index];
}

std::string Hl2ssRecording::format() const { return "hl2ss " + Hl2ssProfileName(config_); }

std::uint64_t Hl2ssRecording::host_ticks(std::size_t index) const { return At(index).timestamp; }
Hl2ssPayloadLayout Hl2ssRecording::layout(std::size_t index) const { return At(index).layout; }
std::uint64_t Hl2ssRecording::packet_offset(std::size_t index) const { return At(index).offset; }

std::uint64_t Hl2ssRecording::AbBlobOffset(const Packet& packet) const {
  const std::uint64_t sizes =
      packet.layout == Hl2ssPayloadLayout::kLegacySame ? 0 : kHl2ssSizeFieldsBytes;
  return packet.offset + kHl2ssPacketHeaderBytes + sizes + packet.size_z;
}

int Hl2ssRecording::measured_gop_frames() const {
  std::optional<std::size_t> first;
  for (std::size_t i = 0; i < index_.size(); ++i) {
    if (!index_[i].key) continue;
    if (first) return static_cast<int>(i - *first);
    first = i;
  }
  return 0;
}

namespace {

double BitsPerSecond(std::uint64_t bytes, std::size_t frames, std::uint64_t first_ticks,
                     std::uint64_t last_ticks) {
  if (frames < 2 || last_ticks <= first_ticks) return 0.0;
  const double frame_interval_s = static_cast<double>(last_ticks - first_ticks) *
                                  kSecondsPerHostTick / static_cast<double>(frames - 1);
  return 8.0 * static_cast<double>(bytes) / static_cast<double>(frames) / frame_interval_s;
}

}  // namespace

std::uint64_t Hl2ssRecording::BlobBytes(std::uint32_t Packet::*size) const {
  std::uint64_t bytes = 0;
  for (const Packet& packet : index_) bytes += packet.*size;
  return bytes;
}

double Hl2ssRecording::ab_bitrate_bps() const {
  if (index_.empty()) return 0.0;
  return BitsPerSecond(BlobBytes(&Packet::size_ab), index_.size(), index_.front().timestamp,
                       index_.back().timestamp);
}

double Hl2ssRecording::zdepth_bitrate_bps() const {
  if (index_.empty()) return 0.0;
  return BitsPerSecond(BlobBytes(&Packet::size_z), index_.size(), index_.front().timestamp,
                       index_.back().timestamp);
}

double Hl2ssRecording::payload_bytes_per_frame() const {
  if (index_.empty()) return 0.0;
  const std::uint64_t bytes = BlobBytes(&Packet::size_ab) + BlobBytes(&Packet::size_z);
  return static_cast<double>(bytes) / static_cast<double>(index_.size());
}

// Frame threads of a recording's decoder: reading ahead, two cores decode 1.5 times the pictures
// a second of one (SAME+H265 at the client's bitrate, docs/benchmarks.md); a recording has no
// latency to keep, unlike a live stream (one thread, stream/).
constexpr int kReadAheadThreads = 2;

AhatFrame Hl2ssRecording::ReadVideoFrame(std::size_t index) const {
  At(index);  // range check
  if (!video_) video_ = std::make_unique<Hl2ssVideoDecoder>(config_, kReadAheadThreads);
  // Go on from the last frame read when no key frame lies between; else from the key frame at or
  // before `index` (or from frame 0, whose unit must then be one).
  std::size_t start = index;
  while (start > 0 && !index_[start].key) --start;
  std::size_t out = next_video_frame_, unit = next_video_unit_;
  if (out == kNone || out > index || out < start) {
    video_->Reset();
    out = unit = start;
  }
  next_video_frame_ = next_video_unit_ = kNone;  // until the decode below has succeeded
  std::vector<std::uint8_t> bytes;
  bool ended = false;
  for (;;) {
    if (video_->ReceivePicture()) {
      if (out++ == index) break;
      continue;  // a frame on the way to `index`: its picture is a reference only
    }
    if (unit < index_.size()) {  // no picture out yet: send the next unit, or end the stream
      const Packet& packet = index_[unit];
      bytes.resize(packet.size_ab);
      ReadAt(AbBlobOffset(packet), bytes, "access unit");
      video_->Send(bytes, {path_, AbBlobOffset(packet), unit});
      ++unit;
    } else if (video_->in_flight() > 0 && !ended) {
      video_->SendEnd();
      ended = true;
    } else {
      throw std::logic_error("Hl2ssRecording: no picture in flight for frame " +
                             std::to_string(index));
    }
  }
  AhatFrame frame = VideoFrameOf(index, *video_);
  next_video_frame_ = index + 1;
  next_video_unit_ = unit;
  return frame;
}

AhatFrame Hl2ssRecording::ReadFrameWith(std::size_t index, Hl2ssVideoDecoder& video) const {
  const Packet& packet = At(index);
  Require(config_.profile_ab != Hl2ssVideoProfile::kRaw, "ReadFrameWith: a RAW recording");
  std::vector<std::uint8_t> unit(packet.size_ab);
  ReadAt(AbBlobOffset(packet), unit, "access unit");
  video.Decode(unit, {path_, AbBlobOffset(packet), index});
  return VideoFrameOf(index, video);
}

AhatFrame Hl2ssRecording::VideoFrameOf(std::size_t index, const Hl2ssVideoDecoder& video) const {
  const Packet& packet = index_[index];
  const std::uint64_t zdepth_offset = AbBlobOffset(packet) - packet.size_z;
  std::vector<std::uint8_t> zdepth(packet.size_z);
  ReadAt(zdepth_offset, zdepth, "Zdepth stream");
  AhatFrame frame;
  frame.host_ticks = packet.timestamp;
  video.FillFrame(zdepth, zdepth_offset, path_, frame);
  ZeroInvalidRange(frame.range_mm);
  ReadTail(packet, AbBlobOffset(packet) + packet.size_ab, frame);
  return frame;
}

AhatFrame Hl2ssRecording::ReadFrame(std::size_t index) const {
  if (config_.profile_ab != Hl2ssVideoProfile::kRaw) return ReadVideoFrame(index);
  const Packet& packet = At(index);
  AhatFrame frame;
  frame.host_ticks = packet.timestamp;
  frame.ab = Image<std::uint16_t>(kAhatWidth, kAhatHeight);
  std::uint64_t cursor = packet.offset + kHl2ssPacketHeaderBytes;
  if (packet.layout != Hl2ssPayloadLayout::kLegacySame) cursor += kHl2ssSizeFieldsBytes;
  if (config_.profile_z == Hl2ssDepthProfile::kSame) {
    frame.range_mm = Image<std::uint16_t>(kAhatWidth, kAhatHeight);
    ReadAt(cursor, AsBytes(frame.range_mm), "RAW depth plane");
    cursor += kHl2ssRawPlaneBytes;
  } else {
    std::vector<std::uint8_t> zdepth(packet.size_z);
    ReadAt(cursor, zdepth, "Zdepth stream");
    frame.range_mm = DecodeZdepth(zdepth, path_, cursor);
    if (frame.range_mm.width() != kAhatWidth || frame.range_mm.height() != kAhatHeight) {
      throw IoError(path_, cursor,
                    "expected a 512 x 512 Zdepth frame, found " +
                        std::to_string(frame.range_mm.width()) + " x " +
                        std::to_string(frame.range_mm.height()));
    }
    frame.depth_step_mm = 2.0;  // exact at 201..749 mm, 2 mm steps above (docs/ahat.md 4.5)
    cursor += packet.size_z;
  }
  ReadAt(cursor, AsBytes(frame.ab), "RAW AB plane");
  cursor += kHl2ssRawPlaneBytes;
  ZeroInvalidRange(frame.range_mm);
  ReadTail(packet, cursor, frame);
  return frame;
}

void Hl2ssRecording::ReadTail(const Packet& packet, std::uint64_t cursor, AhatFrame& frame) const {
  // Sensor ticks (current layout) and the pose (mode 1) follow the AB blob contiguously.
  const bool has_ticks = packet.layout == Hl2ssPayloadLayout::kCurrent;
  const std::uint64_t pose_bytes = config_.mode == 1 ? kHl2ssPoseBytes : 0;
  std::array<std::uint8_t, kHl2ssTicksBytes + kHl2ssPoseBytes> tail{};
  const std::size_t tail_bytes = (has_ticks ? kHl2ssTicksBytes : 0) + pose_bytes;
  ReadAt(cursor, std::span(tail).first(tail_bytes), "sensor ticks and pose");
  if (has_ticks) {
    std::uint64_t ticks;
    std::memcpy(&ticks, tail.data(), sizeof(ticks));
    frame.sensor_ticks_ns = ticks;
    cursor += kHl2ssTicksBytes;
  }
  if (pose_bytes != 0) {
    const auto pose_span =
        std::span(tail).subspan(has_ticks ? kHl2ssTicksBytes : 0).first<kHl2ssPoseBytes>();
    const DirectXMatrix rig_to_world = DirectXFromBytes(pose_span);
    // All zeros when the locator failed; valid <=> pose[15] != 0 (docs/ahat.md section 3.3).
    if (rig_to_world[15] != 0.0f) {
      frame.world_from_rig = RigidFromDirectX(rig_to_world, path_, cursor);
    }
  }
}

std::unique_ptr<Hl2ssRecording> OpenHl2ssRecording(const std::filesystem::path& path) {
  return std::make_unique<Hl2ssRecording>(path);
}

}  // namespace tofnav
