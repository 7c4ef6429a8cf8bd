// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/io/gzip.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tofnav/io/io_error.hpp"

namespace tofnav {
namespace {

std::vector<std::uint8_t> Pattern(std::size_t size) {
  std::vector<std::uint8_t> bytes(size);
  for (std::size_t n = 0; n < size; ++n) bytes[n] = static_cast<std::uint8_t>((n * 7) ^ (n >> 9));
  return bytes;
}

TEST(Gzip, RoundTripAndBoundedOutput) {
  const auto data = Pattern(3 << 20);  // spans several 1 MiB chunks
  const auto compressed = DeflateGzip(data, 1);
  EXPECT_EQ(InflateGzip(compressed, "x.gz", data.size() + 1), data);
  const auto head = InflateGzip(compressed, "x.gz", 1000);
  EXPECT_EQ(head, std::vector<std::uint8_t>(data.begin(), data.begin() + 1000));
}

TEST(Gzip, ConcatenatedMembersAndTrailingPadding) {
  const auto a = Pattern(100), b = Pattern(50);
  auto joined = DeflateGzip(a);
  const auto second = DeflateGzip(b);
  joined.insert(joined.end(), second.begin(), second.end());
  joined.insert(joined.end(), 16, 0);  // zero padding after the last member is ignored
  auto expected = a;
  expected.insert(expected.end(), b.begin(), b.end());
  EXPECT_EQ(InflateGzip(joined, "x.gz", 1000), expected);
}

TEST(Gzip, CorruptAndTruncatedStreamsNameTheOffset) {
  auto compressed = DeflateGzip(Pattern(5000));
  auto cut = compressed;
  cut.resize(cut.size() - 20);
  try {
    InflateGzip(cut, "cut.gz", 10000, 100);
    FAIL();
  } catch (const IoError& error) {
    EXPECT_EQ(error.offset(), 100 + cut.size());
    EXPECT_THAT(error.what(), ::testing::HasSubstr("truncated"));
  }
  compressed[3] = 0xff;  // reserved FLG bits set: zlib rejects the header
  EXPECT_THAT([&] { InflateGzip(compressed, "bad.gz", 10000); },
              ::testing::ThrowsMessage<IoError>(::testing::HasSubstr("corrupt gzip")));
  EXPECT_THROW(InflateGzip(Pattern(10), "plain", 10), IoError);  // no gzip magic
}

}  // namespace
}  // namespace tofnav
