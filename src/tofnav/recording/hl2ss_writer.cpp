// SPDX-License-Identifier: BSD-3-Clause
// hl2ss AHAT recording writer: HL2SSV23 header, AHAT config and current-layout packets.
#include <bit>
#include <cstdint>
#include <stdexcept>

#include "tofnav/core/require.hpp"
#include "tofnav/io/binary.hpp"
#include "tofnav/recording/hl2ss_format.hpp"
#include "tofnav/recording/hl2ss_matrix.hpp"
#include "tofnav/recording/hl2ss_recording.hpp"

namespace tofnav {
namespace {

static_assert(std::endian::native == std::endian::little, "RAW planes are written as held (LE)");

std::vector<std::uint8_t> HeaderBytes(const Hl2ssWriterOptions& options) {
  ByteWriter out;
  out.Text(kHl2ssMagic);
  out.Le<std::uint16_t>(kHl2ssAhatPort);
  out.Le<std::uint32_t>(static_cast<std::uint32_t>(options.user.size()));
  out.Text(options.user);
  out.Le<std::uint8_t>(options.mode);
  out.Le<std::uint8_t>(options.divisor);
  out.Le<std::uint8_t>(static_cast<std::uint8_t>(options.profile_z));
  out.Le<std::uint8_t>(static_cast<std::uint8_t>(options.profile_ab));
  out.Le<std::uint8_t>(options.level);
  out.Le<std::uint32_t>(
      options.bitrate_bps.value_or(Hl2ssDefaultAhatBitrate(options.profile_z, options.profile_ab)));
  out.Le<std::uint8_t>(static_cast<std::uint8_t>(options.encoder_options.size()));
  for (const Hl2ssEncoderOption& option : options.encoder_options) {
    out.Le<std::uint64_t>(option.key);
    out.Le<std::uint64_t>(option.value);
  }
  return out.Release();
}

const std::filesystem::path& CheckedPath(const std::filesystem::path& path,
                                         const Hl2ssWriterOptions& options) {
  options.Check();  // before the temporary file is created
  return path;
}

std::span<const std::uint8_t> AsBytes(std::span<const std::uint16_t> values) {
  return {reinterpret_cast<const std::uint8_t*>(values.data()), values.size_bytes()};
}

}  // namespace

void Hl2ssWriterOptions::Check() const {
  if (mode > 1) throw std::invalid_argument("Hl2ssWriterOptions.mode must be 0 or 1");
  if (divisor < 1) throw std::invalid_argument("Hl2ssWriterOptions.divisor must be >= 1");
  if (profile_z != Hl2ssDepthProfile::kSame && profile_z != Hl2ssDepthProfile::kZdepth) {
    throw std::invalid_argument("Hl2ssWriterOptions.profile_z must be SAME or ZDEPTH");
  }
  if (profile_ab != Hl2ssVideoProfile::kRaw) {
    throw std::invalid_argument("Hl2ssWriterOptions.profile_ab: only RAW can be written");
  }
  if (encoder_options.size() > 255) {
    throw std::invalid_argument("Hl2ssWriterOptions.encoder_options: at most 255 entries");
  }
  if (user.size() > UINT32_MAX) throw std::invalid_argument("Hl2ssWriterOptions.user too long");
  if (profile_z == Hl2ssDepthProfile::kZdepth) zdepth.Check();
}

Hl2ssRecordingWriter::Hl2ssRecordingWriter(const std::filesystem::path& path,
                                           const Hl2ssWriterOptions& options)
    : file_(CheckedPath(path, options)), options_(options) {
  file_.Write(HeaderBytes(options_));
}

void Hl2ssRecordingWriter::Append(const AhatFrame& frame) {
  Require(!closed_, "Append after Close");
  Require(frame.range_mm.width() == kAhatWidth && frame.range_mm.height() == kAhatHeight &&
              frame.ab.width() == kAhatWidth && frame.ab.height() == kAhatHeight,
          "hl2ss AHAT frames are 512 x 512 range and AB images");
  Require(frames_ == 0 || frame.host_ticks >= last_ticks_, "host_ticks must not decrease");

  // Range >= 4090 -> 0, as the server does before sending.
  Image<std::uint16_t> range_mm = frame.range_mm;
  for (std::uint16_t& d : range_mm.pixels()) {
    d = static_cast<std::uint16_t>(d < kAhatInvalidRange ? d : 0);
  }
  std::vector<std::uint8_t> zdepth;
  if (options_.profile_z == Hl2ssDepthProfile::kZdepth) {
    zdepth = EncodeZdepth(range_mm, options_.zdepth);
  }
  const bool same = options_.profile_z == Hl2ssDepthProfile::kSame;
  const std::uint64_t plane_bytes = range_mm.size() * sizeof(std::uint16_t);
  const std::uint64_t size_ab = same ? 2 * plane_bytes : plane_bytes;
  const std::uint64_t payload_size = 8 + zdepth.size() + size_ab + 8;
  Require(payload_size <= UINT32_MAX, "payload too large for hl2ss");

  ByteWriter head;  // packet header and payload size fields
  head.Le<std::uint64_t>(frame.host_ticks);
  head.Le<std::uint32_t>(static_cast<std::uint32_t>(payload_size));
  head.Le<std::uint32_t>(static_cast<std::uint32_t>(zdepth.size()));
  head.Le<std::uint32_t>(static_cast<std::uint32_t>(size_ab));
  file_.Write(head.bytes());
  file_.Write(zdepth);
  if (same) file_.Write(AsBytes(range_mm.pixels()));
  file_.Write(AsBytes(frame.ab.pixels()));

  ByteWriter tail;  // sensor ticks, then the pose in mode 1
  tail.Le<std::uint64_t>(frame.sensor_ticks_ns.value_or(0));
  if (options_.mode == 1) {
    // All zeros marks an unlocated frame (pose[15] == 0), as the server writes it.
    DirectXMatrix rig_to_world{};
    if (frame.world_from_rig) rig_to_world = DirectXFromRigid(*frame.world_from_rig);
    tail.Bytes(BytesFromDirectX(rig_to_world));
  }
  file_.Write(tail.bytes());
  last_ticks_ = frame.host_ticks;
  ++frames_;
}

void Hl2ssRecordingWriter::Close() {
  Require(!closed_, "Close called twice");
  closed_ = true;
  file_.Commit();
}

}  // namespace tofnav
