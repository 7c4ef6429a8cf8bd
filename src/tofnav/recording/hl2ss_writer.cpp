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
  const Hl2ssAhatConfig config = options.Config();
  ByteWriter out;
  out.Text(kHl2ssMagic);
  out.Le<std::uint16_t>(kHl2ssAhatPort);
  out.Le<std::uint32_t>(static_cast<std::uint32_t>(options.user.size()));
  out.Text(options.user);
  out.Le<std::uint8_t>(config.mode);
  out.Le<std::uint8_t>(config.divisor);
  out.Le<std::uint8_t>(static_cast<std::uint8_t>(config.profile_z));
  out.Le<std::uint8_t>(static_cast<std::uint8_t>(config.profile_ab));
  out.Le<std::uint8_t>(config.level);
  out.Le<std::uint32_t>(config.bitrate_bps);
  out.Le<std::uint8_t>(static_cast<std::uint8_t>(config.encoder_options.size()));
  for (const Hl2ssEncoderOption& option : config.encoder_options) {
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
  const auto ab = static_cast<unsigned>(profile_ab);
  if (ab > 3 && profile_ab != Hl2ssVideoProfile::kRaw) {
    throw std::invalid_argument(
        "Hl2ssWriterOptions.profile_ab must be H264 (0-2), H265 (3) or RAW");
  }
  if (bitrate_bps && *bitrate_bps == 0) {
    throw std::invalid_argument("Hl2ssWriterOptions.bitrate_bps must be > 0 (hl2ss refuses 0)");
  }
  if (encoder_options && encoder_options->size() > 255) {
    throw std::invalid_argument("Hl2ssWriterOptions.encoder_options: at most 255 entries");
  }
  if (user.size() > UINT32_MAX) throw std::invalid_argument("Hl2ssWriterOptions.user too long");
  if (profile_z == Hl2ssDepthProfile::kZdepth) zdepth.Check();
}

Hl2ssAhatConfig Hl2ssWriterOptions::Config() const {
  Hl2ssAhatConfig config;
  config.mode = mode;
  config.divisor = divisor;
  config.profile_z = profile_z;
  config.profile_ab = profile_ab;
  config.level = level;
  config.bitrate_bps = bitrate_bps.value_or(Hl2ssDefaultAhatBitrate(profile_z, profile_ab));
  config.encoder_options = encoder_options.value_or(Hl2ssDefaultEncoderOptions(profile_ab));
  return config;
}

Hl2ssPacketEncoder::Hl2ssPacketEncoder(const Hl2ssAhatConfig& config,
                                       const ZdepthEncodeOptions& zdepth)
    : config_(config), zdepth_(zdepth) {
  if (config_.profile_ab != Hl2ssVideoProfile::kRaw) {
    video_ = std::make_unique<H26xEncoder>(Hl2ssEncoderSettings(config_));
  }
}

Hl2ssPacketEncoder::~Hl2ssPacketEncoder() = default;

std::vector<std::uint8_t> Hl2ssPacketEncoder::Encode(const AhatFrame& frame) {
  Require(frame.range_mm.width() == kAhatWidth && frame.range_mm.height() == kAhatHeight &&
              frame.ab.width() == kAhatWidth && frame.ab.height() == kAhatHeight,
          "hl2ss AHAT frames are 512 x 512 range and AB images");
  // Range >= 4090 -> 0, as the server does before sending.
  Image<std::uint16_t> range_mm = frame.range_mm;
  for (std::uint16_t& d : range_mm.pixels()) {
    d = static_cast<std::uint16_t>(d < kAhatInvalidRange ? d : 0);
  }
  std::vector<std::uint8_t> zdepth;
  if (config_.profile_z == Hl2ssDepthProfile::kZdepth) zdepth = EncodeZdepth(range_mm, zdepth_);
  const bool same = config_.profile_z == Hl2ssDepthProfile::kSame;
  std::vector<std::uint8_t> access_unit;  // H26x: one unit per frame (docs/ahat.md 3.6)
  if (video_) {
    access_unit = video_->Encode(same ? PackHl2ssSamePicture(range_mm, frame.ab)
                                      : PackHl2ssZdepthPicture(frame.ab));
  }
  const std::uint64_t plane_bytes = range_mm.size() * sizeof(std::uint16_t);
  const std::uint64_t size_ab =
      video_ ? access_unit.size() : (same ? 2 * plane_bytes : plane_bytes);
  const std::uint64_t payload_size = 8 + zdepth.size() + size_ab + 8;
  Require(payload_size <= UINT32_MAX, "payload too large for hl2ss");
  last_ab_blob_bytes_ = size_ab;

  ByteWriter out;  // packet header and payload size fields
  out.Le<std::uint64_t>(frame.host_ticks);
  out.Le<std::uint32_t>(static_cast<std::uint32_t>(payload_size));
  out.Le<std::uint32_t>(static_cast<std::uint32_t>(zdepth.size()));
  out.Le<std::uint32_t>(static_cast<std::uint32_t>(size_ab));
  out.Bytes(zdepth);
  if (video_) {
    out.Bytes(access_unit);
  } else {
    if (same) out.Bytes(AsBytes(range_mm.pixels()));
    out.Bytes(AsBytes(frame.ab.pixels()));
  }
  // Sensor ticks, then the pose in mode 1.
  out.Le<std::uint64_t>(frame.sensor_ticks_ns.value_or(0));
  if (config_.mode == 1) {
    // All zeros marks an unlocated frame (pose[15] == 0), as the server writes it.
    DirectXMatrix rig_to_world{};
    if (frame.world_from_rig) rig_to_world = DirectXFromRigid(*frame.world_from_rig);
    out.Bytes(BytesFromDirectX(rig_to_world));
  }
  return out.Release();
}

Hl2ssRecordingWriter::Hl2ssRecordingWriter(const std::filesystem::path& path,
                                           const Hl2ssWriterOptions& options)
    : file_(CheckedPath(path, options)),
      options_(options),
      packets_(options.Config(), options.zdepth) {
  file_.Write(HeaderBytes(options_));
}

void Hl2ssRecordingWriter::Append(const AhatFrame& frame) {
  Require(!closed_, "Append after Close");
  Require(frames_ == 0 || frame.host_ticks >= last_ticks_, "host_ticks must not decrease");
  file_.Write(packets_.Encode(frame));
  video_bytes_ += packets_.last_ab_blob_bytes();
  last_ticks_ = frame.host_ticks;
  ++frames_;
}

void Hl2ssRecordingWriter::Close() {
  Require(!closed_, "Close called twice");
  closed_ = true;
  file_.Commit();
}

}  // namespace tofnav
