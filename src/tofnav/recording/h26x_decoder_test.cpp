// SPDX-License-Identifier: BSD-3-Clause
// The H.264 / H.265 decoder's two modes: one thread (each picture out of its own unit, a live
// stream's latency) and frame threads (a recording read ahead): the same pictures, in order, and
// an error that names the unit it belongs to.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

#include "tofnav/io/io_error.hpp"
#include "tofnav/recording/h26x_codec.hpp"

namespace tofnav {
namespace {

// A moving gradient with fine texture: every picture differs and P units carry residuals.
Yuv420Picture Picture(int index) {
  Yuv420Picture p;
  for (int v = 0; v < p.y.height(); ++v) {
    for (int u = 0; u < p.y.width(); ++u) {
      p.y(u, v) = static_cast<std::uint8_t>((u + 2 * v + 3 * index + ((u * v) % 7)) & 0xFF);
    }
  }
  for (int v = 0; v < p.u.height(); ++v) {
    for (int u = 0; u < p.u.width(); ++u) {
      p.u(u, v) = static_cast<std::uint8_t>((u + index) & 0xFF);
      p.v(u, v) = static_cast<std::uint8_t>((v + 5 * index) & 0xFF);
    }
  }
  return p;
}

std::vector<std::vector<std::uint8_t>> Units(H26xCodec codec, int count) {
  H26xEncoder encoder({.codec = codec, .bitrate_bps = 4'000'000});
  std::vector<std::vector<std::uint8_t>> units;
  for (int i = 0; i < count; ++i) units.push_back(encoder.Encode(Picture(i)));
  return units;
}

H26xUnitPlace PlaceOf(std::size_t frame) { return {"units.bin", 1000 * frame, frame}; }

// Sends every unit and then the end, counting the pictures out in `out`: the IoError's message,
// or "" when every unit decoded.
std::string SendAll(H26xCodec codec, int threads,
                    const std::vector<std::vector<std::uint8_t>>& units, std::size_t& out) {
  H26xDecoder decoder(codec, threads);
  Yuv420Picture picture;
  try {
    for (std::size_t i = 0; i < units.size(); ++i) {
      decoder.Send(units[i], PlaceOf(i));
      while (decoder.Receive(picture)) ++out;
    }
    decoder.SendEnd();
    while (decoder.Receive(picture)) ++out;
  } catch (const IoError& e) {
    return e.what();
  }
  return "";
}

class H26xFrameThreads : public ::testing::TestWithParam<H26xCodec> {};

TEST_P(H26xFrameThreads, GiveEveryPictureInOrderAtMostOneUnitLate) {
  const auto units = Units(GetParam(), 8);
  H26xDecoder one(GetParam());
  std::vector<Yuv420Picture> expected(units.size());
  for (std::size_t i = 0; i < units.size(); ++i) one.Decode(units[i], PlaceOf(i), expected[i]);

  H26xDecoder two(GetParam(), 2);
  std::vector<Yuv420Picture> got;
  Yuv420Picture picture;
  for (std::size_t i = 0; i < units.size(); ++i) {
    two.Send(units[i], PlaceOf(i));
    while (two.Receive(picture)) got.push_back(picture);
    // Two frame threads hold at most one picture back (tolerance: none, the decoder's delay).
    EXPECT_GE(got.size() + 1, i + 1) << i;
    EXPECT_EQ(two.in_flight(), i + 1 - got.size());
  }
  two.SendEnd();
  while (two.Receive(picture)) got.push_back(picture);
  EXPECT_EQ(two.in_flight(), 0u);
  ASSERT_EQ(got.size(), expected.size());
  for (std::size_t i = 0; i < got.size(); ++i) EXPECT_EQ(got[i], expected[i]) << i;  // bit exact
  EXPECT_THROW(two.Send(units[0], PlaceOf(0)), std::logic_error);  // ended: Reset first
  two.Reset();
  two.Send(units[0], PlaceOf(0));
  two.SendEnd();
  ASSERT_TRUE(two.Receive(picture));
  EXPECT_EQ(picture, expected[0]);
}

TEST_P(H26xFrameThreads, AnErrorNamesTheUnitItBelongsTo) {
  auto units = Units(GetParam(), 6);
  // Damage the headers of unit 3 (as the recording test does): its own picture fails.
  for (std::size_t i = 6; i < units[3].size(); ++i) {
    units[3][i] = static_cast<std::uint8_t>(0xFF ^ (i * 37));
  }
  std::size_t out = 0;
  const std::string message = SendAll(GetParam(), 2, units, out);
  EXPECT_EQ(out, 3u);  // pictures 0-2 came out before the damaged one
  const std::string codec = GetParam() == H26xCodec::kH265 ? "H.265" : "H.264";
  EXPECT_THAT(message, ::testing::StartsWith("units.bin: at byte 3000: frame 3: " + codec +
                                             " access unit of " + std::to_string(units[3].size()) +
                                             " bytes "));
  // libavcodec's own line, logged by a frame thread, comes with it as with one thread.
  EXPECT_THAT(message, ::testing::HasSubstr(" (libavcodec: "));
}

// The bytes of `unit` before its first slice: its delimiter and parameter sets only.
std::vector<std::uint8_t> HeadersOnly(H26xCodec codec, const std::vector<std::uint8_t>& unit) {
  for (std::size_t i = 3; i + 1 < unit.size(); ++i) {
    if (unit[i] != 1 || unit[i - 1] != 0 || unit[i - 2] != 0) continue;
    const int type = codec == H26xCodec::kH264 ? unit[i + 1] & 0x1F : (unit[i + 1] >> 1) & 0x3F;
    const bool slice = codec == H26xCodec::kH264 ? (type >= 1 && type <= 5) : type <= 21;
    if (slice) {
      const std::size_t start = i >= 3 && unit[i - 3] == 0 ? i - 3 : i - 2;
      return {unit.begin(), unit.begin() + static_cast<std::ptrdiff_t>(start)};
    }
  }
  return unit;
}

TEST_P(H26xFrameThreads, AUnitWithoutAPictureIsNamedNotTheNextOne) {
  const auto encoded = Units(GetParam(), 4);
  // Unit 1 carries parameter sets and no slice: no picture comes of it.
  const std::vector<std::vector<std::uint8_t>> units = {
      encoded[0], HeadersOnly(GetParam(), encoded[0]), encoded[1], encoded[2], encoded[3]};
  ASSERT_LT(units[1].size(), units[0].size());
  for (const int threads : {1, 2}) {
    std::size_t out = 0;
    const std::string message = SendAll(GetParam(), threads, units, out);
    EXPECT_EQ(out, 1u) << threads;  // picture 0, then the unit without one stops the stream
    EXPECT_THAT(message, ::testing::StartsWith("units.bin: at byte 1000: frame 1: ")) << threads;
    // H.265 gives no picture; H.264 says so itself ("no frame!"): either way unit 1 is named.
    EXPECT_THAT(message, ::testing::AnyOf(::testing::HasSubstr(" gave no picture"),
                                          ::testing::HasSubstr(" does not decode: ")))
        << threads;
  }
}

INSTANTIATE_TEST_SUITE_P(Codecs, H26xFrameThreads,
                         ::testing::Values(H26xCodec::kH265, H26xCodec::kH264),
                         [](const auto& test) {
                           return test.param == H26xCodec::kH265 ? "H265" : "H264";
                         });

TEST(H26xDecoder, DecodeAtOnceNeedsOneThreadAndThreadsAreBounded) {
  const auto units = Units(H26xCodec::kH265, 1);
  H26xDecoder two(H26xCodec::kH265, 2);
  Yuv420Picture picture;
  EXPECT_THROW(two.Decode(units[0], PlaceOf(0), picture), std::logic_error);
  EXPECT_THROW(H26xDecoder(H26xCodec::kH265, 0), std::invalid_argument);
  EXPECT_THROW(H26xDecoder(H26xCodec::kH265, 17), std::invalid_argument);
}

}  // namespace
}  // namespace tofnav
