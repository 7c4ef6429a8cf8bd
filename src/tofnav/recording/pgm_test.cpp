// SPDX-License-Identifier: BSD-3-Clause
// 16-bit P5 PGM decoder and encoder against hand-written bytes.
#include "tofnav/recording/pgm.hpp"

#include <gtest/gtest.h>

#include <string>

#include "tofnav/io/io_error.hpp"
#include "tofnav/io/io_test_helpers.hpp"

namespace tofnav {
namespace {

using testing::Bytes;
using testing::ToBytes;

constexpr std::uint64_t kBase = 1000;  // where the PGM starts inside its container (a tar)

Bytes Concat(Bytes a, const Bytes& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

// Offset and message of the IoError thrown by decoding `bytes` at kBase.
std::pair<std::uint64_t, std::string> DecodeError(const Bytes& bytes) {
  try {
    DecodePgm16(bytes, "frames.tar", kBase);
  } catch (const IoError& error) {
    return {error.offset().value_or(0), error.what()};
  }
  ADD_FAILURE() << "no IoError";
  return {0, ""};
}

TEST(DecodePgm16, GenericHeaderWithCommentsAndBigEndianSamples) {
  const Bytes header = ToBytes("P5 # made by hand\n3\t2\r\n# second comment\n65535\n");
  // Samples MSB first: 0x0102 = 258, 0x0FFF = 4095, 0xFFFF, 0, 1, 0x8000.
  const Bytes samples = {0x01, 0x02, 0x0F, 0xFF, 0xFF, 0xFF, 0x00, 0x00, 0x00, 0x01, 0x80, 0x00};
  const Image<std::uint16_t> image = DecodePgm16(Concat(header, samples));
  ASSERT_EQ(image.width(), 3);
  ASSERT_EQ(image.height(), 2);
  EXPECT_EQ(image(0, 0), 258);
  EXPECT_EQ(image(1, 0), 4095);
  EXPECT_EQ(image(2, 0), 65535);
  EXPECT_EQ(image(0, 1), 0);
  EXPECT_EQ(image(1, 1), 1);
  EXPECT_EQ(image(2, 1), 32768);
}

TEST(EncodePgm16, RecorderHeaderAndRoundTrip) {
  Image<std::uint16_t> image(512, 512);
  for (int v = 0; v < 512; ++v) {
    for (int u = 0; u < 512; ++u) image(u, v) = static_cast<std::uint16_t>(u * 131 + v * 977);
  }
  const std::vector<std::uint8_t> bytes = EncodePgm16(image);
  const std::string header = "P5\n512 512\n65535\n";
  ASSERT_EQ(bytes.size(), header.size() + 512 * 512 * 2);
  EXPECT_EQ(std::string(bytes.begin(), bytes.begin() + 17), header);
  // Pixel (3, 1) = 3 * 131 + 977 = 1370 = 0x055A, stored MSB first.
  const std::size_t at = 17 + 2 * (1 * 512 + 3);
  EXPECT_EQ(bytes[at], 0x05);
  EXPECT_EQ(bytes[at + 1], 0x5A);
  EXPECT_EQ(DecodePgm16(bytes), image);
}

TEST(DecodePgm16, ErrorsNameTheAbsoluteOffset) {
  const Bytes samples(12, 0);
  {
    const auto [offset, message] = DecodeError(Concat(ToBytes("P2\n3 2\n65535\n"), samples));
    EXPECT_EQ(offset, kBase);
    EXPECT_NE(message.find("P5"), std::string::npos) << message;
    EXPECT_NE(message.find("frames.tar"), std::string::npos) << message;
  }
  {
    const auto [offset, message] = DecodeError(Concat(ToBytes("P5\n3 2\n255\n"), samples));
    EXPECT_EQ(offset, kBase + 7);  // the maxval digits
    EXPECT_NE(message.find("maxval"), std::string::npos) << message;
  }
  {
    const Bytes short_data(11, 0);
    const auto [offset, message] = DecodeError(Concat(ToBytes("P5\n3 2\n65535\n"), short_data));
    EXPECT_EQ(offset, kBase + 13);  // where the samples start
    EXPECT_NE(message.find("expected 12 bytes"), std::string::npos) << message;
  }
  EXPECT_EQ(DecodeError(Concat(ToBytes("P5\n3 2\n65535\n"), Bytes(13, 0))).first, kBase + 13);
  EXPECT_EQ(DecodeError(ToBytes("P5\n0 2\n65535\n")).first, kBase + 3);            // zero width
  EXPECT_EQ(DecodeError(ToBytes("P5\n3 0\n65535\n")).first, kBase + 5);            // zero height
  EXPECT_EQ(DecodeError(ToBytes("P5\n99999999999 2\n65535\n")).first, kBase + 3);  // too large
  EXPECT_EQ(DecodeError(ToBytes("P53 2\n65535\n")).first, kBase + 2);              // no separator
  EXPECT_EQ(DecodeError(ToBytes("P5\n3x2\n65535\n")).first, kBase + 4);
  EXPECT_EQ(DecodeError(ToBytes("P5\n3 2\n65535")).first, kBase + 12);  // header never ends
  EXPECT_EQ(DecodeError(ToBytes("P5\n3 2 # comment to the end")).first, kBase + 27);
  EXPECT_EQ(DecodeError(ToBytes("P")).first, kBase);
}

}  // namespace
}  // namespace tofnav
