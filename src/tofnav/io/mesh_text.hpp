// SPDX-License-Identifier: BSD-3-Clause
// Internal to io/: tokens of text mesh formats (PLY, STL, OBJ) with line numbers, and numbers.
#pragma once

#include <charconv>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>

namespace tofnav {

/// Whitespace-separated tokens of a byte buffer. Errors are IoErrors at the absolute byte offset
/// of the last token, with "line N: " in front of the message.
class TextScanner {
 public:
  TextScanner(std::span<const std::uint8_t> bytes, std::filesystem::path path)
      : bytes_(bytes), path_(std::move(path)) {}

  /// Next token, crossing line ends; nullopt at the end of the buffer.
  std::optional<std::string_view> NextToken();
  /// Next token; IoError "expected <what>, found the end of the file" at the end.
  std::string_view Token(std::string_view what);
  /// Next token on the current line; nullopt at the line's end (not consumed) or the buffer end.
  std::optional<std::string_view> TokenOnLine();
  /// Moves to just after the next '\n' (or to the end).
  void SkipLine();
  /// Only spaces, tabs and '\r' may remain on the line; consumes its '\n'.
  void ExpectLineEnd(std::string_view after);

  /// The next token parsed as T (integer or floating point); IoError "expected <what>".
  template <typename T>
  T Number(std::string_view what);

  bool AtEnd() const { return position_ >= bytes_.size(); }
  std::size_t position() const { return position_; }
  std::size_t remaining() const { return bytes_.size() - position_; }
  std::size_t line() const { return token_line_; }
  std::size_t token_offset() const { return token_offset_; }
  const std::filesystem::path& path() const { return path_; }
  /// IoError at the last token's offset: "line N: <message>".
  [[noreturn]] void Fail(const std::string& message) const;
  /// "expected <what>, found '<token>'" for the last token.
  [[noreturn]] void FailExpected(std::string_view what) const;

 private:
  std::optional<std::string_view> Scan(bool cross_lines);

  std::span<const std::uint8_t> bytes_;
  std::filesystem::path path_;
  std::size_t position_ = 0;
  std::size_t line_ = 1;  // line of position_
  std::size_t token_offset_ = 0;
  std::size_t token_line_ = 1;
  std::string_view token_;
};

/// Parses the whole token as T (a leading '+' is allowed); false if it is not a T or overflows.
template <typename T>
bool ParseNumber(std::string_view token, T& value) {
  if (token.size() > 1 && token[0] == '+' && token[1] != '-') token.remove_prefix(1);
  const char* end = token.data() + token.size();
  const auto [stop, error] = std::from_chars(token.data(), end, value);
  return error == std::errc() && stop == end;
}

template <typename T>
T TextScanner::Number(std::string_view what) {
  Token(what);
  T value{};
  if (!ParseNumber(token_, value)) FailExpected(what);
  return value;
}

/// `value` as a float; magnitudes beyond the float range become infinities (no UB).
inline float NarrowToFloat(double value) {
  constexpr double kMax = std::numeric_limits<float>::max();
  if (value > kMax) return std::numeric_limits<float>::infinity();
  if (value < -kMax) return -std::numeric_limits<float>::infinity();
  return static_cast<float>(value);
}

/// Shortest decimal text that reads back as exactly `value` ("nan", "inf" as from_chars spells).
void AppendNumber(std::string& out, float value);
void AppendNumber(std::string& out, double value);
/// `token` quoted for an error message, cut to a readable length, non-printables as '?'.
std::string Quote(std::string_view token);
/// ASCII case-insensitive equality.
bool EqualsIgnoreCase(std::string_view a, std::string_view b);

}  // namespace tofnav
