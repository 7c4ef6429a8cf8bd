// SPDX-License-Identifier: BSD-3-Clause
// hl2ss live protocol end to end: replay server -> client, Mode 2, RAW and ZDEPTH, refusals.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>

#include "matchers.hpp"
#include "tofnav/io/file.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/recording/hl2ss_calibration.hpp"
#include "tofnav/stream/hl2ss_client.hpp"
#include "tofnav/stream/hl2ss_replay_server.hpp"
#include "tofnav/stream/hl2ss_test_recording.hpp"

namespace tofnav {
namespace {

constexpr int kFrames = 4;
// How long a client waits for data: the replay server encodes some profiles on the fly, and under
// the sanitizers on a loaded 2-core machine one H.265 frame took over the client's default 5 s
// (session 63). No test here is about timing.
constexpr double kWaitS = 60.0;

struct Case : testing::Hl2ssTestRecording {
  explicit Case(Hl2ssDepthProfile profile) : Hl2ssTestRecording("hl2ss_live", profile, kFrames) {}
  Hl2ssReplayServer Serve() const {
    return Hl2ssReplayServer(recording, dir.path(), {.port = 0, .realtime = false});
  }
};

Hl2ssAhatConfig Config(Hl2ssDepthProfile profile, std::uint8_t mode = 1) {
  return testing::Hl2ssTestConfig(profile, mode);
}

void ExpectSameFrames(Hl2ssAhatClient& client, const Hl2ssRecording& recording, bool poses) {
  for (int i = 0; i < kFrames; ++i) {
    const std::optional<AhatFrame> got = client.Next();
    ASSERT_TRUE(got) << "frame " << i;
    const AhatFrame want = recording.ReadFrame(static_cast<std::size_t>(i));
    EXPECT_EQ(got->host_ticks, want.host_ticks);
    EXPECT_EQ(got->sensor_ticks_ns, want.sensor_ticks_ns);
    EXPECT_TRUE(std::ranges::equal(got->range_mm.pixels(), want.range_mm.pixels()));
    EXPECT_TRUE(std::ranges::equal(got->ab.pixels(), want.ab.pixels()));
    EXPECT_EQ(got->world_from_rig.has_value(), poses && want.world_from_rig.has_value());
    if (poses && want.world_from_rig) {
      EXPECT_THAT(*got->world_from_rig, RigidNear(*want.world_from_rig, 0.0, 0.0));
    }
  }
  EXPECT_FALSE(client.Next());  // the server closes at the end of the recording
}

TEST(Hl2ssLive, RawStreamAndMode2CalibrationMatchTheFiles) {
  const Case c(Hl2ssDepthProfile::kSame);
  Hl2ssReplayServer server = c.Serve();
  const Hl2ssEndpoint endpoint{"127.0.0.1", server.port()};
  const AhatCalibration calibration = DownloadHl2ssCalibration(endpoint);
  EXPECT_EQ(EncodeHl2ssMode2(calibration), ReadHl2ssCalibrationAsMode2(c.dir.path()));
  Hl2ssAhatClient client(endpoint, Config(Hl2ssDepthProfile::kSame), kWaitS);
  ExpectSameFrames(client, Hl2ssRecording(c.recording), true);
  // Mode 0 from a mode-1 recording: the same frames without poses.
  Hl2ssAhatClient no_poses(endpoint, Config(Hl2ssDepthProfile::kSame, 0), kWaitS);
  ExpectSameFrames(no_poses, Hl2ssRecording(c.recording), false);
  EXPECT_EQ(server.stats().streams, 2u);
  EXPECT_EQ(server.stats().calibrations_sent, 1u);
}

TEST(Hl2ssLive, ZdepthStream) {
  const Case c(Hl2ssDepthProfile::kZdepth);
  Hl2ssReplayServer server = c.Serve();
  const Hl2ssEndpoint endpoint{"127.0.0.1", server.port()};
  Hl2ssAhatClient client(endpoint, Config(Hl2ssDepthProfile::kZdepth), kWaitS);
  ExpectSameFrames(client, Hl2ssRecording(c.recording), true);
  // SAME + RAW from a ZDEPTH + RAW recording: encoded on the fly, the same (decoded) frames.
  Hl2ssAhatClient same(endpoint, Config(Hl2ssDepthProfile::kSame), kWaitS);
  ExpectSameFrames(same, Hl2ssRecording(c.recording), true);
  EXPECT_EQ(server.stats().refused, 0u);
}

TEST(Hl2ssLive, ARawRecordingIsServedInTheH265ProfileTheClientAsksFor) {
  const Case c(Hl2ssDepthProfile::kSame);
  Hl2ssReplayServer server = c.Serve();
  const Hl2ssEndpoint endpoint{"127.0.0.1", server.port()};
  Hl2ssAhatConfig config = Config(Hl2ssDepthProfile::kZdepth);
  config.profile_ab = Hl2ssVideoProfile::kH265Main;
  config.bitrate_bps = Hl2ssDefaultAhatBitrate(config.profile_z, config.profile_ab);
  config.encoder_options = Hl2ssDefaultEncoderOptions(config.profile_ab);
  Hl2ssAhatClient client(endpoint, config, kWaitS);
  const Hl2ssRecording recording(c.recording);
  for (int i = 0; i < kFrames; ++i) {
    const std::optional<AhatFrame> got = client.Next();
    ASSERT_TRUE(got) << "frame " << i;
    const AhatFrame want = recording.ReadFrame(static_cast<std::size_t>(i));
    EXPECT_EQ(got->host_ticks, want.host_ticks);
    // Depth through Zdepth is exact below 750 mm (the pattern spans 300-699 mm); AB is lossy.
    EXPECT_TRUE(std::ranges::equal(got->range_mm.pixels(), want.range_mm.pixels()));
    EXPECT_TRUE(got->ab_lossy);
    EXPECT_EQ(got->world_from_rig.has_value(), want.world_from_rig.has_value());
  }
  EXPECT_FALSE(client.Next());
  EXPECT_EQ(client.dropped_frames(), 0);
}

TEST(Hl2ssLive, AnH26xRecordingRefusesAnotherProfile) {
  testing::TempDir dir("hl2ss_live_h265");
  const auto path = dir.path() / "rm_depth_ahat.bin";
  Hl2ssRecordingWriter writer(
      path, {.profile_z = Hl2ssDepthProfile::kZdepth, .profile_ab = Hl2ssVideoProfile::kH265Main});
  for (int i = 0; i < 2; ++i) writer.Append(testing::Hl2ssTestFrame(i));
  writer.Close();
  WriteHl2ssCalibration(dir.path(), MakeSyntheticAhatCalibration());
  Hl2ssReplayServer server(path, dir.path(), {.port = 0, .realtime = false});
  Hl2ssAhatClient wrong({"127.0.0.1", server.port()}, Config(Hl2ssDepthProfile::kZdepth), kWaitS);
  EXPECT_FALSE(wrong.Next());  // RAW asked of an H.265 recording: not re-encoded, closed
  EXPECT_EQ(server.stats().refused, 1u);
}

TEST(Hl2ssLive, AnUndecodableUnitIsADroppedFrameNeverAStaleOne) {
  testing::TempDir dir("hl2ss_live_damaged");
  const auto path = dir.path() / "rm_depth_ahat.bin";
  Hl2ssWriterOptions options{.profile_z = Hl2ssDepthProfile::kZdepth,
                             .profile_ab = Hl2ssVideoProfile::kH265Main};
  options.encoder_options = std::vector<Hl2ssEncoderOption>{{10, 2}};  // key frames 0 and 2
  Hl2ssRecordingWriter writer(path, options);
  for (int i = 0; i < kFrames; ++i) writer.Append(testing::Hl2ssTestFrame(i));
  writer.Close();
  WriteHl2ssCalibration(dir.path(), MakeSyntheticAhatCalibration());
  {  // Damage frame 1's unit after its first NAL header.
    const Hl2ssRecording recording(path);
    auto bytes = ReadFileBytes(path);
    const std::uint64_t packet = recording.packet_offset(1);
    std::uint32_t size_z, size_ab;
    std::memcpy(&size_z, bytes.data() + packet + 12, 4);
    std::memcpy(&size_ab, bytes.data() + packet + 16, 4);
    for (std::uint32_t i = 6; i < size_ab; ++i) {
      bytes[packet + 20 + size_z + i] = static_cast<std::uint8_t>(0xFF ^ (i * 37));
    }
    WriteFileAtomically(path, std::string(bytes.begin(), bytes.end()));
  }
  Hl2ssReplayServer server(path, dir.path(), {.port = 0, .realtime = false});
  Hl2ssAhatConfig config = Config(Hl2ssDepthProfile::kZdepth);
  config.profile_ab = Hl2ssVideoProfile::kH265Main;
  Hl2ssAhatClient client({"127.0.0.1", server.port()}, config, kWaitS);
  std::vector<std::uint64_t> ticks;
  while (const std::optional<AhatFrame> frame = client.Next()) ticks.push_back(frame->host_ticks);
  EXPECT_EQ(ticks, (std::vector<std::uint64_t>{testing::Hl2ssTestFrame(0).host_ticks,
                                               testing::Hl2ssTestFrame(2).host_ticks,
                                               testing::Hl2ssTestFrame(3).host_ticks}));
  EXPECT_EQ(client.dropped_frames(), 1);
  EXPECT_THAT(client.last_drop_reason(), ::testing::HasSubstr("H.265 access unit of "));
}

TEST(Hl2ssLive, ConfigAndUri) {
  const Hl2ssAhatConfig c = Config(Hl2ssDepthProfile::kZdepth);
  const auto bytes = EncodeHl2ssAhatConfig(c);
  EXPECT_EQ(bytes.size(), 10u + 16u);
  EXPECT_EQ(DecodeHl2ssAhatConfig(bytes, "<test>"), c);
  auto bad = bytes;
  bad[0] = 2;
  EXPECT_THROW(DecodeHl2ssAhatConfig(bad, "<test>"), IoError);
  const auto e = ParseHl2ssUri("hl2ss://192.168.1.7:3805");
  ASSERT_TRUE(e);
  EXPECT_EQ(e->host, "192.168.1.7");
  EXPECT_EQ(e->port, 3805);
  EXPECT_EQ(ParseHl2ssUri("hl2ss://hololens")->port, 3804);
  EXPECT_FALSE(ParseHl2ssUri("case/rm_depth_ahat.bin"));
  EXPECT_THROW(ParseHl2ssUri("hl2ss://host:99999"), PreconditionError);
}

}  // namespace
}  // namespace tofnav
