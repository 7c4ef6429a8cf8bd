// SPDX-License-Identifier: BSD-3-Clause
// Golden hl2ss AHAT files assembled byte by byte from docs/ahat.md section 3, read back exactly.
#include "tofnav/recording/hl2ss_recording.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "matchers.hpp"
#include "tofnav/io/file.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/recording/hl2ss_test_files.hpp"

namespace tofnav {
namespace {

using ::testing::HasSubstr;

constexpr double kRotTolRad = 1e-6;   // f32 rotation entries that are exactly 0 and +-1
constexpr double kTransTolMm = 1e-6;  // translations exactly representable in f32 metres

using namespace hl2ss_test;  // NOLINT(google-build-using-namespace): test helpers

void ExpectFramePixels(const AhatFrame& frame, int seed) {
  ASSERT_EQ(frame.range_mm.width(), 512);
  ASSERT_EQ(frame.ab.height(), 512);
  int mismatches = 0;
  for (int v = 0; v < 512; ++v) {
    for (int u = 0; u < 512; ++u) {
      const std::uint16_t raw = DepthAt(seed, u, v);
      const std::uint16_t want = raw >= 4090 ? 0 : raw;
      mismatches += frame.range_mm(u, v) != want || frame.ab(u, v) != AbAt(seed, u, v);
    }
  }
  EXPECT_EQ(mismatches, 0);
  EXPECT_EQ(frame.range_mm(3, 0), 0);
  EXPECT_EQ(frame.range_mm(4, 0), 0);
  EXPECT_EQ(frame.range_mm(5, 0), 0);
  EXPECT_EQ(frame.range_mm(6, 0), 4089);
  EXPECT_EQ(frame.depth_step_mm, 1.0);
}

TEST(Hl2ssRecording, GoldenCurrentSameRawMode1) {
  const auto path = TempPath("current.bin");
  WriteFileAtomically(path, CurrentSameRawMode1().data);
  const auto recording = OpenHl2ssRecording(path);
  EXPECT_EQ(recording->format(), "hl2ss SAME+RAW");
  EXPECT_EQ(std::string(recording->user_data().begin(), recording->user_data().end()), "golden");
  const Hl2ssAhatConfig& config = recording->config();
  EXPECT_EQ(config.mode, 1);
  EXPECT_EQ(config.bitrate_bps, 12345678u);
  EXPECT_EQ(config.encoder_options, (std::vector<Hl2ssEncoderOption>{{10, 1}}));
  ASSERT_EQ(recording->frame_count(), 2u);
  EXPECT_EQ(recording->skipped_empty_packets(), 1u);
  EXPECT_FALSE(recording->truncated_tail());
  EXPECT_FALSE(recording->calibration().has_value());
  EXPECT_EQ(recording->packet_offset(0), kHeaderBytes);

  const AhatFrame first = recording->ReadFrame(0);
  EXPECT_EQ(recording->layout(0), Hl2ssPayloadLayout::kCurrent);
  EXPECT_EQ(first.host_ticks, 1000u);
  EXPECT_EQ(first.sensor_ticks_ns, 111'111'111u);
  ExpectFramePixels(first, 0);
  ASSERT_TRUE(first.world_from_rig.has_value());
  // p_world = [p_rig 1] M: the rig x axis goes to world +y, shifted by t in mm.
  const Eigen::Vector3d x_in_world = *first.world_from_rig * Eigen::Vector3d(1, 0, 0);
  EXPECT_LT((x_in_world - Eigen::Vector3d(250, -499, 1125)).norm(), kTransTolMm);
  const Rigid3d expected(Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ())),
                         Eigen::Vector3d(250, -500, 1125));
  EXPECT_THAT(*first.world_from_rig, RigidNear(expected, kRotTolRad, kTransTolMm));

  const AhatFrame second = recording->ReadFrame(1);
  EXPECT_EQ(second.host_ticks, 2000u);
  EXPECT_EQ(second.sensor_ticks_ns, 222u);
  ExpectFramePixels(second, 1);
  EXPECT_FALSE(second.world_from_rig.has_value());  // all-zero pose: locator failed
  EXPECT_EQ(recording->NearestFrame(1600), 1u);
}

TEST(Hl2ssRecording, GoldenFromMemoryMatchesFile) {
  const Hl2ssRecording recording(CurrentSameRawMode1().data, "memory");
  ASSERT_EQ(recording.frame_count(), 2u);
  ExpectFramePixels(recording.ReadFrame(1), 1);
}

TEST(Hl2ssRecording, GoldenLegacySameRawMode0) {
  Bytes b = Header(0);  // server <= v1.0.29: the payload is the bare 1 MiB blob, no pose
  b.Put<std::uint64_t>(10).Put<std::uint32_t>(kRawPlane * 2).Append(SameRawBlob(2));
  b.Put<std::uint64_t>(20).Put<std::uint32_t>(kRawPlane * 2).Append(SameRawBlob(3));
  const Hl2ssRecording recording(b.data, "legacy");
  ASSERT_EQ(recording.frame_count(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(recording.layout(i), Hl2ssPayloadLayout::kLegacySame);
    const AhatFrame frame = recording.ReadFrame(i);
    EXPECT_EQ(frame.host_ticks, 10u * (i + 1));
    EXPECT_FALSE(frame.sensor_ticks_ns.has_value());
    EXPECT_FALSE(frame.world_from_rig.has_value());
    ExpectFramePixels(frame, 2 + static_cast<int>(i));
  }
}

TEST(Hl2ssRecording, GoldenSizedNoTicksMode1) {
  Bytes b = Header(1);  // server v1.0.30-32: sizes, no sensor ticks
  for (int i = 0; i < 2; ++i) {
    b.Put<std::uint64_t>(5 + static_cast<std::uint64_t>(i)).Put<std::uint32_t>(8 + kRawPlane * 2);
    b.Put<std::uint32_t>(0).Put<std::uint32_t>(kRawPlane * 2).Append(SameRawBlob(i));
    PutPose(b);
  }
  const Hl2ssRecording recording(b.data, "sized");
  ASSERT_EQ(recording.frame_count(), 2u);
  const AhatFrame frame = recording.ReadFrame(1);
  EXPECT_EQ(recording.layout(1), Hl2ssPayloadLayout::kSizedNoTicks);
  EXPECT_FALSE(frame.sensor_ticks_ns.has_value());
  ExpectFramePixels(frame, 1);
  ASSERT_TRUE(frame.world_from_rig.has_value());
  EXPECT_LT(((*frame.world_from_rig).translation - Eigen::Vector3d(250, -500, 1125)).norm(),
            kTransTolMm);
}

}  // namespace
}  // namespace tofnav
