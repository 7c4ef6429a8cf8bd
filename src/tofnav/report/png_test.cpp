// SPDX-License-Identifier: BSD-3-Clause
// EncodePng decodes back to its pixels (chunks, CRCs, zlib IDAT); Base64Encode's RFC vectors.
#include "tofnav/report/png.hpp"

#include <gtest/gtest.h>
#include <zlib.h>

#include <string>

namespace tofnav {
namespace {

std::uint32_t BigEndian32(const std::vector<std::uint8_t>& bytes, std::size_t at) {
  return (std::uint32_t{bytes.at(at)} << 24) | (std::uint32_t{bytes.at(at + 1)} << 16) |
         (std::uint32_t{bytes.at(at + 2)} << 8) | std::uint32_t{bytes.at(at + 3)};
}

struct Chunk {
  std::string type;
  std::vector<std::uint8_t> data;
};

// Splits a PNG into chunks, failing the test on a bad signature or CRC.
std::vector<Chunk> ParseChunks(const std::vector<std::uint8_t>& png) {
  const std::vector<std::uint8_t> signature = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  EXPECT_TRUE(std::equal(signature.begin(), signature.end(), png.begin()));
  std::vector<Chunk> chunks;
  for (std::size_t at = signature.size(); at + 12 <= png.size();) {
    const std::uint32_t length = BigEndian32(png, at);
    const auto* type = png.data() + at + 4;
    const std::uint32_t crc = BigEndian32(png, at + 8 + length);
    EXPECT_EQ(crc, crc32(crc32(0L, Z_NULL, 0), type, length + 4));
    chunks.push_back(
        {std::string(type, type + 4), std::vector<std::uint8_t>(type + 4, type + 4 + length)});
    at += 12 + length;
  }
  return chunks;
}

TEST(EncodePng, DecodesBackToThePixels) {
  Image<Rgb8> image(5, 3);
  for (int v = 0; v < image.height(); ++v) {
    for (int u = 0; u < image.width(); ++u) {
      image(u, v) = Rgb8(static_cast<std::uint8_t>(40 * u), static_cast<std::uint8_t>(80 * v),
                         static_cast<std::uint8_t>(7 * (u + v) + 1));
    }
  }
  const std::vector<Chunk> chunks = ParseChunks(EncodePng(image));
  ASSERT_EQ(chunks.size(), 3u);
  EXPECT_EQ(chunks[0].type, "IHDR");
  EXPECT_EQ(chunks[1].type, "IDAT");
  EXPECT_EQ(chunks[2].type, "IEND");
  EXPECT_TRUE(chunks[2].data.empty());
  const std::vector<std::uint8_t>& ihdr = chunks[0].data;
  ASSERT_EQ(ihdr.size(), 13u);
  EXPECT_EQ(BigEndian32(ihdr, 0), 5u);
  EXPECT_EQ(BigEndian32(ihdr, 4), 3u);
  EXPECT_EQ(std::vector<std::uint8_t>(ihdr.begin() + 8, ihdr.end()),
            (std::vector<std::uint8_t>{8, 2, 0, 0, 0}));  // 8-bit RGB, deflate, no interlace

  std::vector<std::uint8_t> raw(3 * (1 + 5 * 3) + 16);  // room to detect surplus bytes
  uLongf raw_size = raw.size();
  ASSERT_EQ(uncompress(raw.data(), &raw_size, chunks[1].data.data(), chunks[1].data.size()), Z_OK);
  ASSERT_EQ(raw_size, 3u * (1 + 5 * 3));
  for (int v = 0; v < 3; ++v) {
    const std::size_t row = static_cast<std::size_t>(v) * 16;
    EXPECT_EQ(raw[row], 0) << "filter type of row " << v;
    for (int u = 0; u < 5; ++u) {
      for (int k = 0; k < 3; ++k) {
        EXPECT_EQ(raw[row + 1 + 3 * static_cast<std::size_t>(u) + static_cast<std::size_t>(k)],
                  image(u, v)[k])
            << "pixel (" << u << ", " << v << ") channel " << k;
      }
    }
  }
}

TEST(EncodePng, RejectsAnEmptyImage) { EXPECT_THROW(EncodePng(Image<Rgb8>()), PreconditionError); }

TEST(Base64Encode, MatchesTheRfc4648Vectors) {
  const auto encode = [](std::string_view text) {
    return Base64Encode(std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
  };
  EXPECT_EQ(encode(""), "");
  EXPECT_EQ(encode("f"), "Zg==");
  EXPECT_EQ(encode("fo"), "Zm8=");
  EXPECT_EQ(encode("foo"), "Zm9v");
  EXPECT_EQ(encode("foob"), "Zm9vYg==");
  EXPECT_EQ(encode("fooba"), "Zm9vYmE=");
  EXPECT_EQ(encode("foobar"), "Zm9vYmFy");
}

}  // namespace
}  // namespace tofnav
