// SPDX-License-Identifier: BSD-3-Clause
// hl2ss AHAT file constants and payload layout detection, shared by the reader and the writer.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>

#include "tofnav/recording/hl2ss_recording.hpp"

namespace tofnav {

inline constexpr char kHl2ssMagic[] = "HL2SSV23";
constexpr std::size_t kHl2ssMagicBytes = 8;
constexpr std::uint16_t kHl2ssAhatPort = 3804;
constexpr std::uint64_t kHl2ssPacketHeaderBytes = 12;  // u64 timestamp, u32 payload_size
constexpr std::uint64_t kHl2ssSizeFieldsBytes = 8;     // u32 size_z, u32 size_ab
constexpr std::uint64_t kHl2ssTicksBytes = 8;          // u64 sensor_ticks
constexpr std::uint64_t kHl2ssPoseBytes = 64;          // f32[16], mode 1 only
constexpr std::uint64_t kHl2ssGopOptionKey = 10;       // CODECAPI_AVEncMPVGOPSize
constexpr std::uint32_t kHl2ssRawPlaneBytes = kAhatPixels * sizeof(std::uint16_t);

/// Bytes of a RAW AB blob (docs/ahat.md 3.5): depth and AB planes in SAME mode, AB in ZDEPTH.
std::uint32_t Hl2ssRawAbBlobBytes(Hl2ssDepthProfile profile_z);

/// "SAME+RAW", "ZDEPTH+H265_MAIN", ...
std::string Hl2ssProfileName(const Hl2ssAhatConfig& config);

/// The sizes a payload states, by its detected layout.
struct Hl2ssPayloadSizes {
  Hl2ssPayloadLayout layout = Hl2ssPayloadLayout::kLegacySame;
  std::uint32_t size_z = 0;
  std::uint32_t size_ab = 0;  // 0: an empty packet (encoder hiccup), skipped by readers
};

/// Detects a packet's payload layout (docs/ahat.md 3.4) from its payload_size and first payload
/// bytes `head` (8 bytes, fewer only when the payload is shorter), and checks it against the
/// profile. IoError naming `source` and the offending field's offset (the packet starts at
/// `packet_offset`).
Hl2ssPayloadSizes ClassifyHl2ssPayload(const Hl2ssAhatConfig& config, std::uint32_t payload_size,
                                       std::span<const std::uint8_t> head,
                                       const std::filesystem::path& source,
                                       std::uint64_t packet_offset);

}  // namespace tofnav
