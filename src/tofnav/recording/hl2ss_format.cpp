// SPDX-License-Identifier: BSD-3-Clause
// hl2ss AHAT file constants and payload layout detection, shared by the reader and the writer.
#include "tofnav/recording/hl2ss_format.hpp"

#include <cstring>

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
  const double same_factor = profile_z == Hl2ssDepthProfile::kSame ? 16.0 : 1.0;
  return static_cast<std::uint32_t>(512.0 * 512.0 * 45.0 * 12.0 * factor * same_factor);
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
