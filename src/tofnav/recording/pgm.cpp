// SPDX-License-Identifier: BSD-3-Clause
// Binary 16-bit PGM (Netpbm P5) decoder and encoder (docs/ahat.md section 7.3).
#include "tofnav/recording/pgm.hpp"

#include <algorithm>
#include <limits>
#include <string>

#include "tofnav/core/require.hpp"
#include "tofnav/io/io_error.hpp"

namespace tofnav {
namespace {

constexpr std::uint64_t kRequiredMaxval = 65535;
constexpr std::uint64_t kMaxDimension = std::numeric_limits<int>::max();

bool IsSpace(std::uint8_t c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
}

class HeaderParser {
 public:
  HeaderParser(std::span<const std::uint8_t> bytes, const std::filesystem::path& source,
               std::uint64_t base_offset)
      : bytes_(bytes), source_(source), base_offset_(base_offset) {}

  void Magic() {
    if (bytes_.size() < 2 || bytes_[0] != 'P' || bytes_[1] != '5') {
      Fail(0, "expected the binary PGM magic 'P5'");
    }
    position_ = 2;
  }

  // Separator (whitespace and comments, at least one byte), then a decimal number.
  std::uint64_t Number(const char* what) {
    const std::size_t start = position_;
    while (position_ < bytes_.size()) {
      if (IsSpace(bytes_[position_])) {
        ++position_;
      } else if (bytes_[position_] == '#') {  // comment to the end of the line
        while (position_ < bytes_.size() && bytes_[position_] != '\n' &&
               bytes_[position_] != '\r') {
          ++position_;
        }
      } else {
        break;
      }
    }
    if (position_ == start) Fail(position_, std::string("expected whitespace before the ") + what);
    const std::size_t digits = position_;
    number_at_ = digits;
    std::uint64_t value = 0;
    for (; position_ < bytes_.size() && bytes_[position_] >= '0' && bytes_[position_] <= '9';
         ++position_) {
      value = value * 10 + static_cast<std::uint64_t>(bytes_[position_] - '0');
      if (value > kMaxDimension) Fail(digits, std::string("PGM ") + what + " is too large");
    }
    if (position_ == digits) Fail(position_, std::string("expected the PGM ") + what);
    return value;
  }

  // The single whitespace byte that ends the header.
  void EndOfHeader() {
    if (position_ >= bytes_.size() || !IsSpace(bytes_[position_])) {
      Fail(position_, "expected one whitespace byte after the PGM maxval");
    }
    ++position_;
  }

  std::size_t position() const { return position_; }
  std::size_t number_at() const { return number_at_; }  // where the last number's digits start
  [[noreturn]] void Fail(std::size_t at, const std::string& message) const {
    throw IoError(source_, base_offset_ + at, message);
  }

 private:
  std::span<const std::uint8_t> bytes_;
  const std::filesystem::path& source_;
  std::uint64_t base_offset_;
  std::size_t position_ = 0;
  std::size_t number_at_ = 0;
};

}  // namespace

Image<std::uint16_t> DecodePgm16(std::span<const std::uint8_t> bytes,
                                 const std::filesystem::path& source, std::uint64_t base_offset) {
  HeaderParser parser(bytes, source, base_offset);
  parser.Magic();
  const std::uint64_t width = parser.Number("width");
  if (width == 0) parser.Fail(parser.number_at(), "PGM width must be positive");
  const std::uint64_t height = parser.Number("height");
  if (height == 0) parser.Fail(parser.number_at(), "PGM height must be positive");
  const std::uint64_t maxval = parser.Number("maxval");
  if (maxval != kRequiredMaxval) {
    parser.Fail(parser.number_at(),
                "expected PGM maxval 65535 (16-bit samples), found " + std::to_string(maxval));
  }
  parser.EndOfHeader();
  // Both dimensions are below 2^31, so the byte count cannot overflow.
  const std::uint64_t expected = width * height * 2;
  const std::size_t data_at = parser.position();
  const std::uint64_t found = bytes.size() - data_at;
  if (found != expected) {
    parser.Fail(data_at, "expected " + std::to_string(expected) + " bytes of 16-bit samples (" +
                             std::to_string(width) + " x " + std::to_string(height) + "), found " +
                             std::to_string(found));
  }
  Image<std::uint16_t> image(static_cast<int>(width), static_cast<int>(height));
  const std::uint8_t* in = bytes.data() + data_at;
  for (std::uint16_t& sample : image.pixels()) {
    sample = static_cast<std::uint16_t>((in[0] << 8) | in[1]);  // big-endian (MSB first)
    in += 2;
  }
  return image;
}

std::vector<std::uint8_t> EncodePgm16(const Image<std::uint16_t>& image) {
  Require(!image.empty(), "EncodePgm16 needs a non-empty image");
  const std::string header =
      "P5\n" + std::to_string(image.width()) + " " + std::to_string(image.height()) + "\n65535\n";
  std::vector<std::uint8_t> out(header.size() + image.size() * 2);
  std::copy(header.begin(), header.end(), out.begin());
  std::uint8_t* sample_bytes = out.data() + header.size();
  for (const std::uint16_t sample : image.pixels()) {
    *sample_bytes++ = static_cast<std::uint8_t>(sample >> 8);  // big-endian (MSB first)
    *sample_bytes++ = static_cast<std::uint8_t>(sample & 0xFFU);
  }
  return out;
}

}  // namespace tofnav
