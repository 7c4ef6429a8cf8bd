// SPDX-License-Identifier: BSD-3-Clause
// OpenIGTLink codec: big-endian header and bodies, CRC-64/ECMA-182 (docs/openigtlink.md 2.1-2.3).
#include "tofnav/stream/igtl_codec.hpp"

#include <cmath>
#include <cstring>

#include "tofnav/core/require.hpp"
#include "tofnav/io/binary.hpp"
#include "tofnav/io/io_error.hpp"

namespace tofnav {
namespace {

constexpr std::uint64_t kCrcPolynomial = 0x42F0E1EBA9EA3693ULL;
constexpr std::size_t kTypeBytes = 12;
constexpr std::uint16_t kExtendedHeaderBytes = 12;
constexpr std::uint16_t kUsAscii = 3;  // MIBenum

constexpr std::array<std::uint64_t, 256> MakeCrcTable() {
  std::array<std::uint64_t, 256> table{};
  for (std::uint64_t i = 0; i < 256; ++i) {
    std::uint64_t crc = i << 56;
    for (int bit = 0; bit < 8; ++bit) {
      crc = (crc & (1ULL << 63)) != 0 ? (crc << 1) ^ kCrcPolynomial : crc << 1;
    }
    table[i] = crc;
  }
  return table;
}
constexpr std::array<std::uint64_t, 256> kCrcTable = MakeCrcTable();

/// A NUL-padded fixed-width text field (not NUL-terminated when full).
void FixedText(ByteWriter& out, std::string_view text, std::size_t width, const char* field) {
  Require(text.size() <= width, std::string(field) + " '" + std::string(text) + "' exceeds " +
                                    std::to_string(width) + " characters");
  out.Bytes({reinterpret_cast<const std::uint8_t*>(text.data()), text.size()});
  out.bytes().resize(out.bytes().size() + width - text.size(), 0);
}

std::string ReadFixedText(std::span<const std::uint8_t> bytes, const std::filesystem::path& source,
                          std::uint64_t offset, const char* field) {
  std::string text;
  for (const std::uint8_t c : bytes) {
    if (c == 0) break;
    if (c < 0x20 || c > 0x7E) {
      throw IoError(source, offset, std::string("non-printable byte in the ") + field + " field");
    }
    text += static_cast<char>(c);
  }
  return text;
}

void Header(ByteWriter& out, std::uint16_t version, std::string_view type,
            std::string_view device_name, std::uint64_t timestamp,
            std::span<const std::uint8_t> body) {
  out.Be(version);
  FixedText(out, type, kTypeBytes, "message type");
  FixedText(out, device_name, kIgtlMaxDeviceNameBytes, "device name");
  out.Be(timestamp);
  out.Be(static_cast<std::uint64_t>(body.size()));
  out.Be(IgtlCrc64(body));
}

}  // namespace

std::uint64_t IgtlCrc64(std::span<const std::uint8_t> bytes, std::uint64_t crc) {
  for (const std::uint8_t byte : bytes) crc = kCrcTable[((crc >> 56) ^ byte) & 0xFF] ^ (crc << 8);
  return crc;
}

std::uint64_t IgtlTimestamp(double time_s) {
  Require(std::isfinite(time_s) && time_s >= 0.0 && time_s < 4294967296.0,
          "IgtlTimestamp: time outside [0, 2^32) s");
  const double seconds = std::floor(time_s);
  const auto fraction = static_cast<std::uint64_t>(std::ldexp(time_s - seconds, 32));
  return (static_cast<std::uint64_t>(seconds) << 32) |
         std::min<std::uint64_t>(fraction, 0xFFFFFFFFULL);
}

IgtlHeader DecodeIgtlHeader(std::span<const std::uint8_t, kIgtlHeaderBytes> bytes,
                            const std::filesystem::path& source, std::uint64_t offset) {
  ByteReader in(bytes, source, offset);
  IgtlHeader h;
  h.version = in.Be<std::uint16_t>("version");
  if (h.version != 1 && h.version != 2) {
    throw IoError(source, offset,
                  "header version must be 1 or 2, found " + std::to_string(h.version) +
                      " (stream out of sync)");
  }
  h.type = ReadFixedText(in.Take(kTypeBytes, "type"), source, offset + 2, "type");
  if (h.type.empty()) throw IoError(source, offset + 2, "empty message type");
  h.device_name = ReadFixedText(in.Take(kIgtlMaxDeviceNameBytes, "device name"), source,
                                offset + 14, "device name");
  h.timestamp = in.Be<std::uint64_t>("timestamp");
  h.body_size = in.Be<std::uint64_t>("body size");
  h.crc = in.Be<std::uint64_t>("crc");
  return h;
}

std::vector<std::uint8_t> EncodeIgtlMessage(std::string_view type, std::string_view device_name,
                                            std::uint64_t timestamp,
                                            std::span<const std::uint8_t> content) {
  ByteWriter out;
  out.bytes().reserve(kIgtlHeaderBytes + content.size());
  Header(out, 1, type, device_name, timestamp, content);
  out.Bytes(content);
  return out.Release();
}

std::vector<std::uint8_t> EncodeIgtlMessageV2(
    std::string_view type, std::string_view device_name, std::uint64_t timestamp,
    std::span<const std::uint8_t> content,
    std::span<const std::pair<std::string, std::string>> metadata, std::uint32_t message_id) {
  ByteWriter body;
  std::uint32_t meta_bytes = 0;
  for (const auto& [key, value] : metadata) {
    meta_bytes += static_cast<std::uint32_t>(key.size() + value.size());
  }
  body.Be(kExtendedHeaderBytes);
  body.Be(static_cast<std::uint16_t>(2 + 8 * metadata.size()));
  body.Be(meta_bytes);
  body.Be(message_id);
  body.Bytes(content);
  body.Be(static_cast<std::uint16_t>(metadata.size()));
  for (const auto& [key, value] : metadata) {
    body.Be(static_cast<std::uint16_t>(key.size()));
    body.Be(kUsAscii);
    body.Be(static_cast<std::uint32_t>(value.size()));
  }
  for (const auto& [key, value] : metadata) body.Text(key + value);
  ByteWriter out;
  Header(out, 2, type, device_name, timestamp, body.bytes());
  out.Bytes(body.bytes());
  return out.Release();
}

std::array<std::uint8_t, 48> IgtlTransformContent(const Eigen::Matrix<double, 3, 4>& matrix) {
  ByteWriter out;
  for (int col = 0; col < 4; ++col) {
    for (int row = 0; row < 3; ++row) out.Be(static_cast<float>(matrix(row, col)));
  }
  std::array<std::uint8_t, 48> bytes;
  std::memcpy(bytes.data(), out.bytes().data(), bytes.size());
  return bytes;
}

std::array<std::uint8_t, 48> IgtlTransformContent(const Rigid3d& parent_from_child) {
  return IgtlTransformContent(
      Eigen::Matrix<double, 3, 4>(parent_from_child.ToMatrix().topRows<3>()));
}

Rigid3d DecodeIgtlTransformContent(std::span<const std::uint8_t> content,
                                   const std::filesystem::path& source) {
  ByteReader in(content, source);
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  for (int col = 0; col < 4; ++col) {
    for (int row = 0; row < 3; ++row) m(row, col) = in.Be<float>("transform matrix");
  }
  if (!m.allFinite()) throw IoError(source, 0, "non-finite transform");
  try {
    return Rigid3d::FromMatrix(m, 1e-3);  // float32 rotation: orthonormal to ~1e-7
  } catch (const PreconditionError&) {
    throw IoError(source, 0, "transform rotation is not orthonormal");
  }
}

std::vector<std::uint8_t> IgtlPointContent(std::span<const IgtlPoint> points) {
  ByteWriter out;
  for (const IgtlPoint& p : points) {
    FixedText(out, p.name, 64, "point name");
    FixedText(out, p.group, 32, "point group");
    out.Bytes(p.rgba);
    for (int i = 0; i < 3; ++i) out.Be(static_cast<float>(p.position_mm[i]));
    out.Be(static_cast<float>(p.diameter_mm));
    FixedText(out, p.owner, 20, "point owner");
  }
  return out.Release();
}

std::vector<std::uint8_t> IgtlStringContent(std::string_view text) {
  Require(text.size() <= 0xFFFF, "IgtlStringContent: text longer than 65535 bytes");
  ByteWriter out;
  out.Be(kUsAscii);
  out.Be(static_cast<std::uint16_t>(text.size()));
  out.Bytes({reinterpret_cast<const std::uint8_t*>(text.data()), text.size()});
  return out.Release();
}

std::string DecodeIgtlStringContent(std::span<const std::uint8_t> content,
                                    const std::filesystem::path& source) {
  ByteReader in(content, source);
  in.Be<std::uint16_t>("string encoding");
  const auto length = in.Be<std::uint16_t>("string length");
  const auto text = in.Take(length, "string");
  return {text.begin(), text.end()};
}

std::vector<std::uint8_t> IgtlPolyDataContent(const TriangleMesh& mesh) {
  Require(mesh.vertices.size() < 0x40000000 && mesh.triangles.size() < 0x10000000,
          "IgtlPolyDataContent: mesh too large for 32-bit counts");
  const auto points = static_cast<std::uint32_t>(mesh.vertices.size());
  const auto polygons = static_cast<std::uint32_t>(mesh.triangles.size());
  ByteWriter out;
  out.bytes().reserve(40 + 12 * std::size_t{points} + 16 * std::size_t{polygons});
  // NPOINTS, NVERTICES, SIZE_VERTICES, NLINES, SIZE_LINES, NPOLYGONS, SIZE_POLYGONS,
  // NTRIANGLE_STRIPS, SIZE_TRIANGLE_STRIPS, NATTRIBUTES
  for (const std::uint32_t count : {points, 0u, 0u, 0u, 0u, polygons, polygons * 16u, 0u, 0u, 0u}) {
    out.Be(count);
  }
  for (const Eigen::Vector3d& v : mesh.vertices) {
    for (int i = 0; i < 3; ++i) out.Be(static_cast<float>(v[i]));
  }
  for (const Eigen::Vector3i& t : mesh.triangles) {
    out.Be(3u);
    for (int i = 0; i < 3; ++i) {
      Require(t[i] >= 0 && static_cast<std::uint32_t>(t[i]) < points,
              "IgtlPolyDataContent: triangle index out of range");
      out.Be(static_cast<std::uint32_t>(t[i]));
    }
  }
  return out.Release();
}

}  // namespace tofnav
