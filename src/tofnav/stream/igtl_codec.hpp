// SPDX-License-Identifier: BSD-3-Clause
// OpenIGTLink wire codec (docs/openigtlink.md section 2): header, CRC-64, TRANSFORM/POINT/STRING/
// POLYDATA bodies. Pure functions over bytes, byte-identical to libopenigtlink 1.11 Pack().
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "tofnav/core/rigid3d.hpp"
#include "tofnav/core/triangle_mesh.hpp"

namespace tofnav {

constexpr std::size_t kIgtlHeaderBytes = 58;
constexpr std::size_t kIgtlMaxDeviceNameBytes = 20;

/// CRC-64/ECMA-182 as OpenIGTLink uses it (MSB first, init `crc`, no final XOR).
std::uint64_t IgtlCrc64(std::span<const std::uint8_t> bytes, std::uint64_t crc = 0);

/// OpenIGTLink time stamp of a time in seconds: (seconds << 32) | fraction * 2^32.
std::uint64_t IgtlTimestamp(double time_s);

/// The fixed 58-byte header, decoded.
struct IgtlHeader {
  std::uint16_t version = 1;  // 1: protocol 1/2; 2: extended header + metadata (protocol 3)
  std::string type;           // "TRANSFORM", "STATUS", ... (NULs stripped)
  std::string device_name;    // up to 20 characters
  std::uint64_t timestamp = 0;
  std::uint64_t body_size = 0;
  std::uint64_t crc = 0;
};

/// Decodes a header; IoError (naming `source` and `offset`) when the version is not 1 or 2 or a
/// name field holds a non-printable character (a stream out of sync).
IgtlHeader DecodeIgtlHeader(std::span<const std::uint8_t, kIgtlHeaderBytes> bytes,
                            const std::filesystem::path& source, std::uint64_t offset);

/// A whole version-1 message: header (CRC of `content`) then `content`. PreconditionError when
/// the type exceeds 12 or the device name 20 characters.
std::vector<std::uint8_t> EncodeIgtlMessage(std::string_view type, std::string_view device_name,
                                            std::uint64_t timestamp,
                                            std::span<const std::uint8_t> content);
/// The same as a version-2 message (what 3D Slicer sends): extended header (12 bytes,
/// `message_id`), content, metadata header and metadata (key, value pairs, values as US-ASCII).
std::vector<std::uint8_t> EncodeIgtlMessageV2(
    std::string_view type, std::string_view device_name, std::uint64_t timestamp,
    std::span<const std::uint8_t> content,
    std::span<const std::pair<std::string, std::string>> metadata, std::uint32_t message_id = 0);

/// TRANSFORM body: 12 float32, the 3 x 3 block column-major, then the translation [mm].
std::array<std::uint8_t, 48> IgtlTransformContent(const Eigen::Matrix<double, 3, 4>& matrix);
std::array<std::uint8_t, 48> IgtlTransformContent(const Rigid3d& parent_from_child);
Rigid3d DecodeIgtlTransformContent(std::span<const std::uint8_t> content,
                                   const std::filesystem::path& source = "<igtl>");

/// One POINT element (136 bytes on the wire).
struct IgtlPoint {
  std::string name;   // up to 64 characters
  std::string group;  // up to 32
  std::array<std::uint8_t, 4> rgba = {255, 255, 0, 255};
  Eigen::Vector3d position_mm = Eigen::Vector3d::Zero();
  double diameter_mm = 2.0;
  std::string owner;  // up to 20
};
std::vector<std::uint8_t> IgtlPointContent(std::span<const IgtlPoint> points);

/// STRING body, US-ASCII (MIBenum 3); PreconditionError above 65535 bytes.
std::vector<std::uint8_t> IgtlStringContent(std::string_view text);
std::string DecodeIgtlStringContent(std::span<const std::uint8_t> content,
                                    const std::filesystem::path& source = "<igtl>");

/// POLYDATA body of a triangle mesh: points as float32, triangles as polygons, no attributes.
std::vector<std::uint8_t> IgtlPolyDataContent(const TriangleMesh& mesh);

}  // namespace tofnav
