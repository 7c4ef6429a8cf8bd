// SPDX-License-Identifier: BSD-3-Clause
// Bounds-checked little/big-endian decoding of byte buffers, shared by the io/ readers.
// Every failure is an IoError naming the file and the absolute byte offset.
#pragma once

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <span>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "tofnav/io/io_error.hpp"

namespace tofnav {

/// Reads values sequentially from a byte span that starts at `base_offset` in `path`.
class ByteReader {
 public:
  ByteReader(std::span<const std::uint8_t> bytes, std::filesystem::path path,
             std::uint64_t base_offset = 0)
      : bytes_(bytes), path_(std::move(path)), base_offset_(base_offset) {}

  /// Little-endian arithmetic value; `what` names the field in the error message.
  template <typename T>
  T Le(const char* what) {
    static_assert(std::is_arithmetic_v<T>);
    T value;
    std::memcpy(&value, Take(sizeof(T), what).data(), sizeof(T));
    if constexpr (std::endian::native == std::endian::big && sizeof(T) > 1) value = Swap(value);
    return value;
  }
  /// Big-endian arithmetic value.
  template <typename T>
  T Be(const char* what) {
    T value = Le<T>(what);
    return sizeof(T) > 1 ? Swap(value) : value;
  }
  /// The next `count` bytes.
  std::span<const std::uint8_t> Take(std::size_t count, const char* what) {
    if (count > bytes_.size() - position_) {
      Fail(std::string("expected ") + std::to_string(count) + " bytes of " + what + ", found " +
           std::to_string(bytes_.size() - position_) + " before the end");
    }
    const auto out = bytes_.subspan(position_, count);
    position_ += count;
    return out;
  }
  void Skip(std::size_t count, const char* what) { Take(count, what); }

  std::size_t position() const { return position_; }
  std::size_t remaining() const { return bytes_.size() - position_; }
  std::uint64_t absolute_offset() const { return base_offset_ + position_; }
  const std::filesystem::path& path() const { return path_; }
  /// Throws IoError at the current offset.
  [[noreturn]] void Fail(const std::string& message) const {
    throw IoError(path_, absolute_offset(), message);
  }

 private:
  template <typename T>
  static T Swap(T value) {
    std::uint8_t raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));
    for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(raw[i], raw[sizeof(T) - 1 - i]);
    std::memcpy(&value, raw, sizeof(T));
    return value;
  }

  std::span<const std::uint8_t> bytes_;
  std::filesystem::path path_;
  std::uint64_t base_offset_ = 0;
  std::size_t position_ = 0;
};

/// Appends little-endian values to a byte vector (writers).
class ByteWriter {
 public:
  template <typename T>
  void Le(T value) {
    static_assert(std::is_arithmetic_v<T>);
    const std::size_t at = bytes_.size();
    bytes_.resize(at + sizeof(T));
    std::memcpy(bytes_.data() + at, &value, sizeof(T));
    if constexpr (std::endian::native == std::endian::big) {
      std::reverse(bytes_.begin() + static_cast<std::ptrdiff_t>(at), bytes_.end());
    }
  }
  template <typename T>
  void Be(T value) {
    Le(value);
    std::reverse(bytes_.end() - static_cast<std::ptrdiff_t>(sizeof(T)), bytes_.end());
  }
  void Bytes(std::span<const std::uint8_t> data) {
    bytes_.insert(bytes_.end(), data.begin(), data.end());
  }
  void Text(const std::string& text) { bytes_.insert(bytes_.end(), text.begin(), text.end()); }

  std::vector<std::uint8_t>& bytes() { return bytes_; }
  std::vector<std::uint8_t> Release() { return std::move(bytes_); }

 private:
  std::vector<std::uint8_t> bytes_;
};

}  // namespace tofnav
