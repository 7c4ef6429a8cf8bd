// SPDX-License-Identifier: BSD-3-Clause
// hl2ss live protocol end to end: replay server -> client, Mode 2, RAW and ZDEPTH, refusals.
#include <gtest/gtest.h>

#include <algorithm>

#include "matchers.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/recording/hl2ss_calibration.hpp"
#include "tofnav/stream/hl2ss_client.hpp"
#include "tofnav/stream/hl2ss_replay_server.hpp"
#include "tofnav/stream/hl2ss_test_recording.hpp"

namespace tofnav {
namespace {

constexpr int kFrames = 4;

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
  Hl2ssAhatClient client(endpoint, Config(Hl2ssDepthProfile::kSame));
  ExpectSameFrames(client, Hl2ssRecording(c.recording), true);
  // Mode 0 from a mode-1 recording: the same frames without poses.
  Hl2ssAhatClient no_poses(endpoint, Config(Hl2ssDepthProfile::kSame, 0));
  ExpectSameFrames(no_poses, Hl2ssRecording(c.recording), false);
  EXPECT_EQ(server.stats().streams, 2u);
  EXPECT_EQ(server.stats().calibrations_sent, 1u);
}

TEST(Hl2ssLive, ZdepthStreamAndRefusedProfile) {
  const Case c(Hl2ssDepthProfile::kZdepth);
  Hl2ssReplayServer server = c.Serve();
  const Hl2ssEndpoint endpoint{"127.0.0.1", server.port()};
  Hl2ssAhatClient client(endpoint, Config(Hl2ssDepthProfile::kZdepth));
  ExpectSameFrames(client, Hl2ssRecording(c.recording), true);
  Hl2ssAhatClient wrong(endpoint, Config(Hl2ssDepthProfile::kSame));  // not recorded: closed
  EXPECT_FALSE(wrong.Next());
  EXPECT_EQ(server.stats().refused, 1u);
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
