// SPDX-License-Identifier: BSD-3-Clause
// PLY header parsing (Turk's PLY format, version 1.0).
#include "tofnav/mesh/ply_header.hpp"

#include <array>
#include <optional>
#include <string_view>
#include <utility>

namespace tofnav {
namespace {

struct TypeName {
  std::string_view name;
  PlyType type;
};

// Both the original names and the sized aliases of later PLY writers.
constexpr std::array<TypeName, 16> kTypeNames = {{
    {"char", PlyType::kInt8},
    {"int8", PlyType::kInt8},
    {"uchar", PlyType::kUint8},
    {"uint8", PlyType::kUint8},
    {"short", PlyType::kInt16},
    {"int16", PlyType::kInt16},
    {"ushort", PlyType::kUint16},
    {"uint16", PlyType::kUint16},
    {"int", PlyType::kInt32},
    {"int32", PlyType::kInt32},
    {"uint", PlyType::kUint32},
    {"uint32", PlyType::kUint32},
    {"float", PlyType::kFloat32},
    {"float32", PlyType::kFloat32},
    {"double", PlyType::kFloat64},
    {"float64", PlyType::kFloat64},
}};

std::optional<PlyType> LookupType(std::string_view token) {
  for (const TypeName& entry : kTypeNames) {
    if (entry.name == token) return entry.type;
  }
  return std::nullopt;
}

PlyType ParseType(TextScanner& scanner, std::string_view what) {
  const std::optional<PlyType> type = LookupType(scanner.Token(what));
  if (!type) {
    scanner.FailExpected(
        std::string(what) +
        " (char, uchar, short, ushort, int, uint, float, double, int8 ... float64)");
  }
  return *type;
}

PlyFormat ParseFormat(TextScanner& scanner) {
  const std::string_view token = scanner.Token("a PLY format");
  PlyFormat format = PlyFormat::kAscii;
  if (token == "binary_little_endian") {
    format = PlyFormat::kBinaryLittleEndian;
  } else if (token == "binary_big_endian") {
    format = PlyFormat::kBinaryBigEndian;
  } else if (token != "ascii") {
    scanner.FailExpected("ascii, binary_little_endian or binary_big_endian");
  }
  if (scanner.Token("the PLY version") != "1.0") scanner.FailExpected("PLY version 1.0");
  scanner.ExpectLineEnd("the format");
  return format;
}

PlyElement ParseElement(TextScanner& scanner, std::size_t offset, std::size_t line) {
  PlyElement element;
  element.header_offset = offset;
  element.header_line = line;
  element.name = std::string(scanner.Token("an element name"));
  element.count = scanner.Number<std::uint64_t>("an element count");
  scanner.ExpectLineEnd("the element count");
  return element;
}

PlyProperty ParseProperty(TextScanner& scanner, const PlyElement& element) {
  PlyProperty property;
  const std::string_view first = scanner.Token("a property type");
  if (first == "list") {
    property.is_list = true;
    property.count_type = ParseType(scanner, "a list count type");
    if (!IsIntegerType(property.count_type)) scanner.FailExpected("an integer list count type");
    property.type = ParseType(scanner, "a list item type");
  } else {
    const std::optional<PlyType> type = LookupType(first);
    if (!type) scanner.FailExpected("a property type or 'list'");
    property.type = *type;
  }
  property.name = std::string(scanner.Token("a property name"));
  property.what = "element '" + element.name + "' property '" + property.name + "'";
  scanner.ExpectLineEnd("the property name");
  return property;
}

}  // namespace

std::size_t PlyTypeSize(PlyType type) {
  constexpr std::array<std::size_t, 8> kSizes = {1, 1, 2, 2, 4, 4, 4, 8};
  return kSizes[static_cast<std::size_t>(type)];
}

bool IsIntegerType(PlyType type) { return type != PlyType::kFloat32 && type != PlyType::kFloat64; }

double PlyTypeMin(PlyType type) {
  constexpr std::array<double, 6> kMin = {-128.0, 0.0, -32768.0, 0.0, -2147483648.0, 0.0};
  return kMin[static_cast<std::size_t>(type)];
}

double PlyTypeMax(PlyType type) {
  constexpr std::array<double, 6> kMax = {127.0,   255.0,        32767.0,
                                          65535.0, 2147483647.0, 4294967295.0};
  return kMax[static_cast<std::size_t>(type)];
}

PlyHeader ParsePlyHeader(TextScanner& scanner) {
  if (scanner.NextToken() != "ply") scanner.FailExpected("'ply' (the PLY magic)");
  scanner.ExpectLineEnd("'ply'");
  PlyHeader header;
  bool has_format = false;
  while (true) {
    const std::optional<std::string_view> keyword = scanner.TokenOnLine();
    if (!keyword) {
      if (scanner.AtEnd()) scanner.Fail("expected 'end_header', found the end of the file");
      scanner.SkipLine();  // blank line
      continue;
    }
    if (*keyword == "comment" || *keyword == "obj_info") {
      scanner.SkipLine();
    } else if (*keyword == "format") {
      if (has_format) scanner.Fail("a second 'format' line");
      header.format = ParseFormat(scanner);
      has_format = true;
    } else if (*keyword == "element") {
      const std::size_t offset = scanner.token_offset();
      const std::size_t line = scanner.line();
      header.elements.push_back(ParseElement(scanner, offset, line));
      for (std::size_t i = 0; i + 1 < header.elements.size(); ++i) {
        if (header.elements[i].name == header.elements.back().name) {
          scanner.Fail("a second element '" + header.elements.back().name + "'");
        }
      }
    } else if (*keyword == "property") {
      if (header.elements.empty()) scanner.Fail("a property before any element");
      header.elements.back().properties.push_back(ParseProperty(scanner, header.elements.back()));
    } else if (*keyword == "end_header") {
      if (!has_format) scanner.Fail("expected a 'format' line before 'end_header'");
      scanner.ExpectLineEnd("'end_header'");
      return header;
    } else {
      scanner.FailExpected(
          "a PLY header keyword (format, comment, obj_info, element, property, "
          "end_header)");
    }
  }
}

}  // namespace tofnav
