// SPDX-License-Identifier: BSD-3-Clause
// hl2ss AHAT file constants and payload layout detection, shared by the reader and the writer.
#include "tofnav/recording/hl2ss_format.hpp"

#include <algorithm>
#include <cstring>
#include <utility>

#include "tofnav/core/require.hpp"
#include "tofnav/io/io_error.hpp"

namespace tofnav {
namespace {

// A Zdepth stream or H26x access unit far beyond any real frame: a larger size is corruption.
constexpr std::uint64_t kMaxCompressedBytes = std::uint64_t{8} << 20;

std::uint32_t U32At(std::span<const std::uint8_t> bytes, std::size_t offset) {
  std::uint32_t value;
  std::memcpy(&value, bytes.data() + offset, sizeof(value));
  return value;
}

std::string VideoProfileName(Hl2ssVideoProfile profile) {
  switch (profile) {
    case Hl2ssVideoProfile::kH264Base:
      return "H264_BASE";
    case Hl2ssVideoProfile::kH264Main:
      return "H264_MAIN";
    case Hl2ssVideoProfile::kH264High:
      return "H264_HIGH";
    case Hl2ssVideoProfile::kH265Main:
      return "H265_MAIN";
    case Hl2ssVideoProfile::kRaw:
      return "RAW";
  }
  return "?";
}

}  // namespace

std::uint32_t Hl2ssRawAbBlobBytes(Hl2ssDepthProfile profile_z) {
  return profile_z == Hl2ssDepthProfile::kSame ? 2 * kHl2ssRawPlaneBytes : kHl2ssRawPlaneBytes;
}

std::string Hl2ssProfileName(const Hl2ssAhatConfig& config) {
  return (config.profile_z == Hl2ssDepthProfile::kSame ? "SAME+" : "ZDEPTH+") +
         VideoProfileName(config.profile_ab);
}

std::uint32_t Hl2ssDefaultAhatBitrate(Hl2ssDepthProfile profile_z, Hl2ssVideoProfile profile_ab) {
  double factor = 1.0;  // dimensionless: bits per 12-bit pixel
  if (profile_ab == Hl2ssVideoProfile::kH265Main) {
    factor = 1.0 / 150.0;
  } else if (profile_ab != Hl2ssVideoProfile::kRaw) {
    factor = 1.0 / 75.0;
  }
  // The client truncates the one-picture rate to an integer, then multiplies by 16 in SAME mode.
  const auto bitrate = static_cast<std::uint32_t>(512.0 * 512.0 * 45.0 * 12.0 * factor);
  return profile_z == Hl2ssDepthProfile::kSame ? 16 * bitrate : bitrate;
}

namespace {

constexpr std::pair<Hl2ssVideoProfile, const char*> kVideoNames[] = {
    {Hl2ssVideoProfile::kRaw, "raw"},
    {Hl2ssVideoProfile::kH265Main, "h265"},
    {Hl2ssVideoProfile::kH264Main, "h264"},
    {Hl2ssVideoProfile::kH264Base, "h264-base"},
    {Hl2ssVideoProfile::kH264High, "h264-high"},
};

}  // namespace

std::optional<Hl2ssStreamProfile> ParseHl2ssStreamProfile(const std::string& text) {
  if (text == "raw") return Hl2ssStreamProfile{Hl2ssDepthProfile::kSame, Hl2ssVideoProfile::kRaw};
  if (text == "zdepth") {
    return Hl2ssStreamProfile{Hl2ssDepthProfile::kZdepth, Hl2ssVideoProfile::kRaw};
  }
  const std::size_t plus = text.find('+');
  if (plus == std::string::npos) return std::nullopt;
  const std::string depth = text.substr(0, plus);
  const std::string video = text.substr(plus + 1);
  Hl2ssStreamProfile profile;
  if (depth == "same") {
    profile.profile_z = Hl2ssDepthProfile::kSame;
  } else if (depth != "zdepth") {
    return std::nullopt;
  }
  if (video == "h264-main") {
    profile.profile_ab = Hl2ssVideoProfile::kH264Main;
    return profile;
  }
  for (const auto& [value, name] : kVideoNames) {
    if (video == name) {
      profile.profile_ab = value;
      return profile;
    }
  }
  return std::nullopt;
}

std::string Hl2ssStreamProfileName(const Hl2ssStreamProfile& profile) {
  if (profile.profile_ab == Hl2ssVideoProfile::kRaw) {  // the names tofnav has always used
    return profile.profile_z == Hl2ssDepthProfile::kSame ? "raw" : "zdepth";
  }
  std::string name = profile.profile_z == Hl2ssDepthProfile::kSame ? "same+" : "zdepth+";
  for (const auto& [value, video] : kVideoNames) {
    if (value == profile.profile_ab) return name + video;
  }
  return name + "?";
}

std::string Hl2ssStreamProfileChoices() {
  std::string text;
  for (const Hl2ssDepthProfile depth : {Hl2ssDepthProfile::kZdepth, Hl2ssDepthProfile::kSame}) {
    for (const auto& [value, video] : kVideoNames) {
      text += (text.empty() ? "" : ", ") + Hl2ssStreamProfileName({depth, value});
    }
  }
  return text;
}

H26xCodec Hl2ssVideoCodec(Hl2ssVideoProfile profile_ab) {
  return profile_ab == Hl2ssVideoProfile::kH265Main ? H26xCodec::kH265 : H26xCodec::kH264;
}

std::vector<Hl2ssEncoderOption> Hl2ssDefaultEncoderOptions(Hl2ssVideoProfile profile_ab) {
  return {{kHl2ssGopOptionKey, profile_ab == Hl2ssVideoProfile::kRaw ? 1u : 45u}};
}

int Hl2ssGopFrames(const Hl2ssAhatConfig& config) {
  for (const Hl2ssEncoderOption& option : config.encoder_options) {
    if (option.key == kHl2ssGopOptionKey) {
      return static_cast<int>(std::clamp<std::uint64_t>(option.value, 1, 100000));
    }
  }
  return static_cast<int>(Hl2ssDefaultEncoderOptions(config.profile_ab)[0].value);
}

H26xEncoderOptions Hl2ssEncoderSettings(const Hl2ssAhatConfig& config) {
  Require(config.profile_ab != Hl2ssVideoProfile::kRaw, "Hl2ssEncoderSettings: a RAW profile");
  H26xEncoderOptions options;
  options.codec = Hl2ssVideoCodec(config.profile_ab);
  if (config.profile_ab == Hl2ssVideoProfile::kH264Base) {
    options.h264_profile = H264Profile::kBaseline;
  } else if (config.profile_ab == Hl2ssVideoProfile::kH264High) {
    options.h264_profile = H264Profile::kHigh;
  }
  options.bitrate_bps = config.bitrate_bps;
  options.gop_frames = Hl2ssGopFrames(config);
  options.divisor = std::max<int>(config.divisor, 1);
  return options;
}

Hl2ssPayloadSizes ClassifyHl2ssPayload(const Hl2ssAhatConfig& config, std::uint32_t payload_size,
                                       std::span<const std::uint8_t> head,
                                       const std::filesystem::path& source,
                                       std::uint64_t packet_offset) {
  const bool same = config.profile_z == Hl2ssDepthProfile::kSame;
  const bool raw = config.profile_ab == Hl2ssVideoProfile::kRaw;
  const std::uint64_t max_payload =
      kHl2ssSizeFieldsBytes + kHl2ssTicksBytes + (same ? 0 : kMaxCompressedBytes) +
      (raw ? Hl2ssRawAbBlobBytes(config.profile_z) : kMaxCompressedBytes);
  const std::uint64_t size_field = packet_offset + 8;
  if (payload_size > max_payload) {
    throw IoError(source, size_field,
                  "payload_size " + std::to_string(payload_size) +
                      " exceeds the largest possible AHAT payload of this profile (" +
                      std::to_string(max_payload) + " bytes)");
  }
  Hl2ssPayloadSizes sizes{.layout = Hl2ssPayloadLayout::kLegacySame, .size_ab = payload_size};
  std::string stated;  // for the error message
  if (payload_size >= kHl2ssSizeFieldsBytes) {
    const std::uint32_t size_z = U32At(head, 0);
    const std::uint32_t size_ab = U32At(head, 4);
    const std::uint64_t sized = kHl2ssSizeFieldsBytes + size_z + size_ab;
    if (sized + kHl2ssTicksBytes == payload_size) {
      sizes = {Hl2ssPayloadLayout::kCurrent, size_z, size_ab};
    } else if (sized == payload_size) {
      sizes = {Hl2ssPayloadLayout::kSizedNoTicks, size_z, size_ab};
    }
    stated = " (size_z " + std::to_string(size_z) + ", size_ab " + std::to_string(size_ab) + ")";
  }
  if (sizes.layout == Hl2ssPayloadLayout::kLegacySame) {
    // Only SAME mode had bare payloads, and a bare RAW blob has a fixed size.
    if (!same || (raw && payload_size != Hl2ssRawAbBlobBytes(config.profile_z))) {
      throw IoError(source, size_field,
                    "payload_size " + std::to_string(payload_size) +
                        " matches no AHAT payload layout of this profile" + stated);
    }
  } else if (sizes.size_ab != 0) {
    const std::uint64_t payload = packet_offset + kHl2ssPacketHeaderBytes;
    if (same && sizes.size_z != 0) {
      throw IoError(source, payload,
                    "size_z must be 0 in SAME mode, found " + std::to_string(sizes.size_z));
    }
    if (raw && sizes.size_ab != Hl2ssRawAbBlobBytes(config.profile_z)) {
      throw IoError(source, payload + 4,
                    "size_ab must be " + std::to_string(Hl2ssRawAbBlobBytes(config.profile_z)) +
                        " for a RAW AB blob, found " + std::to_string(sizes.size_ab));
    }
  }
  return sizes;
}

}  // namespace tofnav
