// SPDX-License-Identifier: BSD-3-Clause
// Internal to io/: PLY body values, binary (either byte order) or ascii, with bounds and errors.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>

#include "tofnav/io/binary.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/mesh/ply_header.hpp"

namespace tofnav {

/// Values of a binary body in the header's byte order; errors at the value's absolute offset.
class BinarySource {
 public:
  BinarySource(std::span<const std::uint8_t> bytes, const std::filesystem::path& path,
               std::size_t body_offset, bool big_endian)
      : reader_(bytes.subspan(body_offset), path, body_offset), big_endian_(big_endian) {}

  double Value(PlyType type, const std::string& what) {
    offset_ = reader_.absolute_offset();
    switch (type) {
      case PlyType::kInt8:
        return Get<std::int8_t>(what);
      case PlyType::kUint8:
        return Get<std::uint8_t>(what);
      case PlyType::kInt16:
        return Get<std::int16_t>(what);
      case PlyType::kUint16:
        return Get<std::uint16_t>(what);
      case PlyType::kInt32:
        return Get<std::int32_t>(what);
      case PlyType::kUint32:
        return Get<std::uint32_t>(what);
      case PlyType::kFloat32:
        return Get<float>(what);
      case PlyType::kFloat64:
        return Get<double>(what);
    }
    Fail("unknown PLY type");
  }
  void SkipItems(std::uint64_t count, const PlyProperty& list) {
    const std::size_t size = PlyTypeSize(list.type);
    if (count > reader_.remaining() / size) {
      Fail("a list of " + std::to_string(count) + " items of " + list.what +
           " runs past the end (" + std::to_string(reader_.remaining()) + " bytes remain)");
    }
    reader_.Skip(static_cast<std::size_t>(count) * size, list.what.c_str());
  }
  /// IoError unless `element.count` instances of their smallest size fit in what remains.
  void CheckCount(const PlyElement& element) {
    std::size_t min_bytes = 0;
    for (const PlyProperty& p : element.properties) {
      min_bytes += PlyTypeSize(p.is_list ? p.count_type : p.type);
    }
    if (min_bytes > 0 && element.count > reader_.remaining() / min_bytes) {
      offset_ = reader_.absolute_offset();
      Fail("element '" + element.name + "' (header line " + std::to_string(element.header_line) +
           ") declares " + std::to_string(element.count) + " instances of at least " +
           std::to_string(min_bytes) + " bytes, but only " + std::to_string(reader_.remaining()) +
           " bytes remain");
    }
  }
  [[noreturn]] void Fail(const std::string& message) const {
    throw IoError(reader_.path(), offset_, message);
  }

 private:
  template <typename T>
  double Get(const std::string& what) {
    const T value = big_endian_ ? reader_.Be<T>(what.c_str()) : reader_.Le<T>(what.c_str());
    return static_cast<double>(value);
  }

  ByteReader reader_;
  bool big_endian_ = false;
  std::uint64_t offset_ = 0;
};

/// Values of an ascii body: whitespace-separated tokens; errors name the line.
class AsciiSource {
 public:
  explicit AsciiSource(TextScanner& scanner) : scanner_(scanner) {}

  double Value(PlyType type, const std::string& what) {
    const std::string_view token = scanner_.Token(what);
    if (type == PlyType::kFloat32) return Parse<float>(token, "a float", what);
    if (type == PlyType::kFloat64) return Parse<double>(token, "a double", what);
    const double value = static_cast<double>(Parse<std::int64_t>(token, "an integer", what));
    if (value < PlyTypeMin(type) || value > PlyTypeMax(type)) {
      Fail(Quote(token) + " is out of range for " + what);
    }
    return value;
  }
  void SkipItems(std::uint64_t count, const PlyProperty& list) {
    for (std::uint64_t i = 0; i < count; ++i) Value(list.type, list.what);
  }
  /// A token takes at least one character and one separator.
  void CheckCount(const PlyElement& element) {
    const std::size_t min_bytes = 2 * element.properties.size();
    if (min_bytes > 0 && element.count > (scanner_.remaining() + 1) / min_bytes) {
      throw IoError(scanner_.path(), scanner_.position(),
                    "element '" + element.name + "' (header line " +
                        std::to_string(element.header_line) + ") declares " +
                        std::to_string(element.count) + " instances, more than the " +
                        std::to_string(scanner_.remaining()) + " remaining bytes can hold");
    }
  }
  [[noreturn]] void Fail(const std::string& message) const { scanner_.Fail(message); }

 private:
  template <typename T>
  T Parse(std::string_view token, const char* kind, const std::string& what) {
    T value{};
    if (!ParseNumber(token, value)) scanner_.FailExpected(std::string(kind) + " for " + what);
    return value;
  }

  TextScanner& scanner_;
};

/// The item count of a list property; IoError when it is negative.
template <typename Source>
std::uint64_t ListCount(Source& source, const PlyProperty& list) {
  const double count = source.Value(list.count_type, list.what);
  if (count < 0.0) source.Fail("negative list count for " + list.what);
  return static_cast<std::uint64_t>(count);
}

}  // namespace tofnav
