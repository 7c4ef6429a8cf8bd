// SPDX-License-Identifier: BSD-3-Clause
// Tokens with line numbers and exact number text for the text mesh formats.
#include "tofnav/io/mesh_text.hpp"

#include <array>

#include "tofnav/io/io_error.hpp"

namespace tofnav {
namespace {

bool IsSpace(std::uint8_t c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f';
}

template <typename T>
void AppendShortest(std::string& out, T value) {
  std::array<char, 64> text{};
  const auto result = std::to_chars(text.data(), text.data() + text.size(), value);
  out.append(text.data(), result.ptr);
}

}  // namespace

std::optional<std::string_view> TextScanner::Scan(bool cross_lines) {
  while (position_ < bytes_.size() && IsSpace(bytes_[position_])) {
    if (bytes_[position_] == '\n') {
      if (!cross_lines) break;
      ++line_;
    }
    ++position_;
  }
  token_offset_ = position_;
  token_line_ = line_;
  if (position_ >= bytes_.size() || bytes_[position_] == '\n') {
    token_ = {};
    return std::nullopt;
  }
  const std::size_t start = position_;
  while (position_ < bytes_.size() && !IsSpace(bytes_[position_])) ++position_;
  token_ =
      std::string_view(reinterpret_cast<const char*>(bytes_.data()) + start, position_ - start);
  return token_;
}

std::optional<std::string_view> TextScanner::NextToken() { return Scan(true); }

std::optional<std::string_view> TextScanner::TokenOnLine() { return Scan(false); }

std::string_view TextScanner::Token(std::string_view what) {
  const auto token = Scan(true);
  if (!token) Fail("expected " + std::string(what) + ", found the end of the file");
  return *token;
}

void TextScanner::SkipLine() {
  while (position_ < bytes_.size() && bytes_[position_] != '\n') ++position_;
  if (position_ < bytes_.size()) {
    ++position_;
    ++line_;
  }
}

void TextScanner::ExpectLineEnd(std::string_view after) {
  if (TokenOnLine()) Fail("expected the end of the line after " + std::string(after));
  SkipLine();
}

void TextScanner::Fail(const std::string& message) const {
  throw IoError(path_, token_offset_, "line " + std::to_string(token_line_) + ": " + message);
}

void TextScanner::FailExpected(std::string_view what) const {
  Fail("expected " + std::string(what) + ", found " + Quote(token_));
}

void AppendNumber(std::string& out, float value) { AppendShortest(out, value); }
void AppendNumber(std::string& out, double value) { AppendShortest(out, value); }

std::string Quote(std::string_view token) {
  constexpr std::size_t kMaxShownChars = 32;  // enough to recognise a token in a message
  std::string out = "'";
  for (std::size_t i = 0; i < token.size() && i < kMaxShownChars; ++i) {
    const char c = token[i];
    out += (c >= 0x20 && c < 0x7f) ? c : '?';
  }
  if (token.size() > kMaxShownChars) out += "...";
  return out + "'";
}

bool EqualsIgnoreCase(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const auto lower = [](char c) {
      return (c >= 'A' && c <= 'Z') ? static_cast<char>(c + 32) : c;
    };
    if (lower(a[i]) != lower(b[i])) return false;
  }
  return true;
}

}  // namespace tofnav
