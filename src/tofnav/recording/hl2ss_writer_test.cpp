// SPDX-License-Identifier: BSD-3-Clause
// hl2ss writer: byte-exact against a hand-assembled file, and writer -> reader round trips.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "matchers.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/io/file.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/recording/hl2ss_recording.hpp"
#include "tofnav/recording/hl2ss_test_files.hpp"

namespace tofnav {
namespace {

using namespace hl2ss_test;  // NOLINT(google-build-using-namespace): test helpers

constexpr double kPoseRotTolRad = 1e-6;   // f32 rotation entries: ~1e-7 rounding
constexpr double kPoseTransTolMm = 1e-3;  // f32 metres at ~1 m: 6e-5 mm per ulp

AhatFrame PatternFrame(int seed, std::uint64_t host_ticks) {
  AhatFrame frame;
  frame.host_ticks = host_ticks;
  frame.range_mm = Image<std::uint16_t>(512, 512);
  frame.ab = Image<std::uint16_t>(512, 512);
  for (int v = 0; v < 512; ++v) {
    for (int u = 0; u < 512; ++u) {
      frame.range_mm(u, v) = DepthAt(seed, u, v);
      frame.ab(u, v) = AbAt(seed, u, v);
    }
  }
  return frame;
}

void ExpectPixels(const AhatFrame& read, const AhatFrame& written) {
  int mismatches = 0;
  for (std::size_t i = 0; i < read.range_mm.size(); ++i) {
    const std::uint16_t d = written.range_mm.pixels()[i];
    mismatches += read.range_mm.pixels()[i] != (d >= 4090 ? 0 : d);
    mismatches += read.ab.pixels()[i] != written.ab.pixels()[i];
  }
  EXPECT_EQ(mismatches, 0);
}

TEST(Hl2ssRecordingWriter, BytesMatchHandAssembledFile) {
  // The same file as Header(1) + one current-layout packet, built independently of the writer.
  AhatFrame frame = PatternFrame(4, 77);
  for (std::uint16_t& d : frame.range_mm.pixels()) d = static_cast<std::uint16_t>(d % 4090);
  frame.sensor_ticks_ns = 0x0102030405060708;
  // 180 deg about z: the quaternion (0, 0, 0, 1) gives exact 0 and -1 entries.
  frame.world_from_rig =
      Rigid3d(Eigen::Quaterniond(0, 0, 0, 1), Eigen::Vector3d(250.0, -500.0, 1125.0));
  Bytes expected = Header(1);
  expected.Put<std::uint64_t>(77).Put<std::uint32_t>(16 + 2 * kRawPlane);
  expected.Put<std::uint32_t>(0).Put<std::uint32_t>(2 * kRawPlane);
  for (const std::uint16_t d : frame.range_mm.pixels()) expected.Put(d);
  for (const std::uint16_t a : frame.ab.pixels()) expected.Put(a);
  expected.Put<std::uint64_t>(0x0102030405060708);
  for (const float value :
       {-1.f, 0.f, 0.f, 0.f, 0.f, -1.f, 0.f, 0.f, 0.f, 0.f, 1.f, 0.f, 0.25f, -0.5f, 1.125f, 1.f}) {
    expected.PutF(value);
  }

  const auto path = TempPath("writer.bin");
  Hl2ssWriterOptions options;
  options.bitrate_bps = 12345678;
  options.user = "golden";
  Hl2ssRecordingWriter writer(path, options);
  writer.Append(frame);
  writer.Close();
  const auto bytes = ReadFileBytes(path);
  ASSERT_EQ(bytes.size(), expected.data.size());
  EXPECT_TRUE(bytes == expected.data);
  // Spot-check the start against the layout itself: magic, port 3804 = 0x0EDC, user_len 6.
  const std::vector<std::uint8_t> head(bytes.begin(), bytes.begin() + 14);
  EXPECT_EQ(head, (std::vector<std::uint8_t>{'H', 'L', '2', 'S', 'S', 'V', '2', '3', 0xDC, 0x0E, 6,
                                             0, 0, 0}));
}

TEST(Hl2ssRecordingWriter, DefaultBitrateIsTheClientDefault) {
  // int(512 * 512 * 45 * 12 * f), then times 16 in SAME mode (docs/ahat.md 3.6.4).
  EXPECT_EQ(Hl2ssDefaultAhatBitrate(Hl2ssDepthProfile::kSame, Hl2ssVideoProfile::kH265Main),
            15'099'488u);
  EXPECT_EQ(Hl2ssDefaultAhatBitrate(Hl2ssDepthProfile::kSame, Hl2ssVideoProfile::kH264Main),
            30'198'976u);
  EXPECT_EQ(Hl2ssDefaultAhatBitrate(Hl2ssDepthProfile::kZdepth, Hl2ssVideoProfile::kH265Main),
            943'718u);
  EXPECT_EQ(Hl2ssDefaultAhatBitrate(Hl2ssDepthProfile::kZdepth, Hl2ssVideoProfile::kRaw),
            141'557'760u);
}

TEST(Hl2ssRecordingWriter, RawMode1RoundTripIsExact) {
  const auto path = TempPath("mode1.bin");
  std::vector<AhatFrame> frames = {PatternFrame(0, 100), PatternFrame(1, 100),
                                   PatternFrame(2, 350)};
  frames[0].sensor_ticks_ns = 123456789;
  frames[0].world_from_rig =
      Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized())),
              Eigen::Vector3d(123.4, -567.8, 901.2));
  frames[2].world_from_rig = Rigid3d::Identity();
  Hl2ssRecordingWriter writer(path);
  for (const AhatFrame& frame : frames) writer.Append(frame);
  writer.Close();

  const Hl2ssRecording recording(path);
  EXPECT_EQ(recording.config().bitrate_bps, 2'264'924'160u);  // SAME + RAW default
  EXPECT_EQ(std::string(recording.user_data().begin(), recording.user_data().end()),
            "created by tofnav");
  ASSERT_EQ(recording.frame_count(), frames.size());
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const AhatFrame read = recording.ReadFrame(i);
    EXPECT_EQ(read.host_ticks, frames[i].host_ticks);
    EXPECT_EQ(read.sensor_ticks_ns, frames[i].sensor_ticks_ns.value_or(0));
    ExpectPixels(read, frames[i]);
    ASSERT_EQ(read.world_from_rig.has_value(), frames[i].world_from_rig.has_value()) << i;
    if (read.world_from_rig) {
      EXPECT_THAT(*read.world_from_rig,
                  RigidNear(*frames[i].world_from_rig, kPoseRotTolRad, kPoseTransTolMm));
    }
  }
}

TEST(Hl2ssRecordingWriter, RawMode0StoresNoPose) {
  const auto path = TempPath("mode0.bin");
  Hl2ssWriterOptions options;
  options.mode = 0;
  AhatFrame frame = PatternFrame(3, 5);
  frame.world_from_rig = Rigid3d::Identity();
  Hl2ssRecordingWriter writer(path, options);
  writer.Append(frame);
  writer.Append(PatternFrame(4, 6));
  writer.Close();
  const Hl2ssRecording recording(path);
  EXPECT_EQ(std::filesystem::file_size(path),
            8 + 2 + 4 + options.user.size() + 10 + 16 + 2 * (12 + 16 + 2 * kRawPlane));
  ASSERT_EQ(recording.frame_count(), 2u);
  const AhatFrame read = recording.ReadFrame(0);
  EXPECT_FALSE(read.world_from_rig.has_value());
  ExpectPixels(read, frame);
  ExpectPixels(recording.ReadFrame(1), PatternFrame(4, 6));
}

TEST(Hl2ssRecordingWriter, ZdepthRoundTripWithinQuantisation) {
  const auto path = TempPath("zdepth.bin");
  Hl2ssWriterOptions options;
  options.profile_z = Hl2ssDepthProfile::kZdepth;
  const AhatFrame frame = PatternFrame(5, 9);
  Hl2ssRecordingWriter writer(path, options);
  writer.Append(frame);
  writer.Close();
  const Hl2ssRecording recording(path);
  EXPECT_EQ(recording.format(), "hl2ss ZDEPTH+RAW");
  ASSERT_EQ(recording.frame_count(), 1u);
  const AhatFrame read = recording.ReadFrame(0);
  EXPECT_EQ(read.depth_step_mm, 2.0);
  int mismatches = 0;
  int exact_band = 0;
  for (std::size_t i = 0; i < read.range_mm.size(); ++i) {
    const std::uint16_t d = frame.range_mm.pixels()[i];
    const std::uint16_t valid = d >= 4090 ? 0 : d;
    const std::uint16_t got = read.range_mm.pixels()[i];
    mismatches += got != ZdepthRoundTripMm(valid) || read.ab.pixels()[i] != frame.ab.pixels()[i];
    if (valid >= 201 && valid <= 749) {
      ++exact_band;
      mismatches += got != valid;  // docs/ahat.md 4.5: lossless at 201..749 mm
    }
  }
  EXPECT_EQ(mismatches, 0);
  EXPECT_GT(exact_band, 100'000);
}

TEST(Hl2ssRecordingWriter, AbandonedWriterLeavesNoFile) {
  const auto path = TempPath("abandoned.bin");
  {
    Hl2ssRecordingWriter writer(path);
    writer.Append(PatternFrame(0, 1));
  }
  EXPECT_FALSE(std::filesystem::exists(path));
  EXPECT_TRUE(std::filesystem::is_empty(path.parent_path()));
}

TEST(Hl2ssRecordingWriter, RejectsBadInput) {
  const auto path = TempPath("bad.bin");
  Hl2ssWriterOptions zero_bitrate;
  zero_bitrate.profile_ab = Hl2ssVideoProfile::kH264Main;
  zero_bitrate.bitrate_bps = 0;  // hl2ss refuses 0, even for RAW
  EXPECT_THROW(Hl2ssRecordingWriter(path, zero_bitrate), std::invalid_argument);
  Hl2ssWriterOptions unknown;
  unknown.profile_ab = static_cast<Hl2ssVideoProfile>(7);
  EXPECT_THROW(Hl2ssRecordingWriter(path, unknown), std::invalid_argument);
  EXPECT_FALSE(std::filesystem::exists(path));
  Hl2ssRecordingWriter writer(path);
  writer.Append(PatternFrame(0, 10));
  EXPECT_THROW(writer.Append(PatternFrame(0, 9)), PreconditionError);  // ticks decrease
  AhatFrame small = PatternFrame(0, 11);
  small.ab = Image<std::uint16_t>(4, 4);
  EXPECT_THROW(writer.Append(small), PreconditionError);
}

}  // namespace
}  // namespace tofnav
