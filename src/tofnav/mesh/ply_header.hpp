// SPDX-License-Identifier: BSD-3-Clause
// Internal to io/: the PLY header (format, elements, scalar and list properties).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "tofnav/io/mesh_text.hpp"

namespace tofnav {

enum class PlyType : std::uint8_t {
  kInt8,
  kUint8,
  kInt16,
  kUint16,
  kInt32,
  kUint32,
  kFloat32,
  kFloat64
};
enum class PlyFormat : std::uint8_t { kAscii, kBinaryLittleEndian, kBinaryBigEndian };

std::size_t PlyTypeSize(PlyType type);
bool IsIntegerType(PlyType type);
/// Smallest and largest value of an integer type (as double, exact for these types).
double PlyTypeMin(PlyType type);
double PlyTypeMax(PlyType type);

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::kFloat32;  // the value type (of the items, for a list)
  bool is_list = false;
  PlyType count_type = PlyType::kUint8;  // lists only; always an integer type
  std::string what;                      // "element 'vertex' property 'x'" for messages
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
  std::size_t header_offset = 0;  // byte offset and line of its "element" line
  std::size_t header_line = 0;
};

struct PlyHeader {
  PlyFormat format = PlyFormat::kAscii;
  std::vector<PlyElement> elements;
};

/// Parses "ply" ... "end_header" and leaves `scanner` at the first byte of the body.
PlyHeader ParsePlyHeader(TextScanner& scanner);

}  // namespace tofnav
