// SPDX-License-Identifier: BSD-3-Clause
// The live link against the fault-injecting replay server: each fault is reported word for word,
// the link reconnects, and it ends only on a stop, a give-up or another device.
#include "tofnav/stream/live_link.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/socket.h>

#include <array>
#include <thread>

#include "tofnav/recording/hl2ss_format.hpp"
#include "tofnav/stream/hl2ss_replay_server.hpp"
#include "tofnav/stream/hl2ss_test_recording.hpp"

namespace tofnav {
namespace {

using ::testing::MatchesRegex;

/// Short times keep the tests fast; the defaults (1 s, 0.2 s to 2 s) are the same code.
LiveLinkOptions FastLink() {
  return {.stall_timeout_s = 0.2,
          .first_backoff_s = 0.05,
          .max_backoff_s = 0.4,
          .report_period_s = 0.05};
}

/// A looped recording served as fast as the client reads, with `faults`, and a live source.
struct Link {
  testing::Hl2ssTestRecording recorded;
  Hl2ssReplayServer server;
  std::string uri;
  std::vector<LinkReport> reports;
  std::atomic<bool> stop{false};
  std::unique_ptr<LiveHl2ssSource> source;

  Link(const std::string& tag, const std::string& faults,
       const LiveLinkOptions& options = FastLink(),
       std::optional<std::vector<std::uint8_t>> device_calibration = {})
      : recorded(tag, Hl2ssDepthProfile::kSame, 4),
        server(recorded.recording, recorded.dir.path(),
               {.port = 0,
                .realtime = false,
                .loop = true,
                .faults = {.faults = ParseReplayFaults(faults)}}),
        uri("hl2ss://127.0.0.1:" + std::to_string(server.port())) {
    source = std::make_unique<LiveHl2ssSource>(
        Hl2ssEndpoint{"127.0.0.1", server.port()},
        testing::Hl2ssTestConfig(Hl2ssDepthProfile::kSame), options, std::move(device_calibration),
        [this](const LinkReport& r) { reports.push_back(r); }, &stop);
  }
  std::vector<std::string> Messages() const {
    std::vector<std::string> out;
    for (const LinkReport& r : reports) {
      if (!r.message.empty()) out.push_back(r.message);
    }
    return out;
  }
  /// Reads `count` frames, each later than the one before (the timeline continues).
  void ExpectFrames(int count) {
    for (int i = 0; i < count; ++i) {
      const std::optional<AhatFrame> frame = source->Next();
      ASSERT_TRUE(frame) << "frame " << i << ": " << source->failure();
      EXPECT_GT(frame->host_ticks, last_ticks);
      last_ticks = frame->host_ticks;
    }
  }
  std::uint64_t last_ticks = 0;
};

constexpr const char* kBack =
    ": the stream is back after [0-9]+\\.[0-9] s without frames; "
    "navigating again";

TEST(LiveLink, DropIsReportedAndTheSameDeviceReconnected) {
  testing::Hl2ssTestRecording calibration_source("live_drop_cal", Hl2ssDepthProfile::kSame, 1);
  Link link("live_drop", "drop:after=3", FastLink(),
            ReadHl2ssCalibrationAsMode2(calibration_source.dir.path()));
  link.ExpectFrames(5);
  const std::vector<std::string> m = link.Messages();
  ASSERT_EQ(m.size(), 2u);
  EXPECT_EQ(m[0], link.uri + ": the headset closed the stream after 3 frames; reconnecting");
  EXPECT_THAT(m[1], MatchesRegex(link.uri + kBack));
  const LiveLinkStats s = link.source->stats();
  EXPECT_EQ(s.disconnects, 1);
  EXPECT_EQ(s.reconnects, 1);
  EXPECT_EQ(s.stalls, 0);
  EXPECT_GE(s.down_s, 0.05);  // at least the first back-off
  EXPECT_TRUE(link.reports.front().changed && !link.reports.front().up);
}

TEST(LiveLink, TruncatedPacketIsReported) {
  Link link("live_truncate", "truncate:after=3");
  link.ExpectFrames(5);
  const std::vector<std::string> m = link.Messages();
  ASSERT_EQ(m.size(), 2u);
  EXPECT_EQ(m[0], link.uri + ": the stream broke off inside a packet after 3 frames; reconnecting");
  EXPECT_THAT(m[1], MatchesRegex(link.uri + kBack));
  EXPECT_EQ(link.source->stats().disconnects, 1);
}

TEST(LiveLink, ResetIsReported) {
  Link link("live_reset", "reset:after=3");
  link.ExpectFrames(5);
  const std::vector<std::string> m = link.Messages();
  ASSERT_EQ(m.size(), 2u);
  // A reset discards what the server had not sent yet: 0 to 3 frames got through.
  EXPECT_THAT(m[0],
              MatchesRegex(link.uri + ": the headset reset the connection after [0-3] frames; "
                                      "reconnecting"));
  EXPECT_THAT(m[1], MatchesRegex(link.uri + kBack));
  EXPECT_EQ(link.source->stats().disconnects, 1);
}

TEST(LiveLink, StallIsReportedAfterTheStallTimeout) {
  Link link("live_stall", "stall:600ms:after=3");
  link.ExpectFrames(5);
  const std::vector<std::string> m = link.Messages();
  ASSERT_GE(m.size(), 3u);
  EXPECT_EQ(m[0], link.uri + ": no frame from the headset for 0.2 s after 3 frames; reconnecting");
  // The first attempt (after 0.05 s) waits 0.2 s in the server's queue while it still stalls.
  EXPECT_EQ(m[1], link.uri +
                      ": reconnecting failed (the headset accepted but sent nothing for 0.2 s); "
                      "trying again every 0.4 s at most");
  EXPECT_THAT(m.back(), MatchesRegex(link.uri + kBack));
  const LiveLinkStats s = link.source->stats();
  EXPECT_EQ(s.stalls, 1);
  EXPECT_EQ(s.disconnects, 0);
  EXPECT_EQ(s.reconnects, 1);
  EXPECT_GE(s.failed_attempts, 1);
}

TEST(LiveLink, RestartIsWaitedOut) {
  Link link("live_restart", "restart:500ms:after=3");
  link.ExpectFrames(5);
  const std::vector<std::string> m = link.Messages();
  ASSERT_EQ(m.size(), 3u);
  EXPECT_EQ(m[0], link.uri + ": the headset closed the stream after 3 frames; reconnecting");
  EXPECT_EQ(m[1], link.uri +
                      ": reconnecting failed (the headset refuses connections: is the hl2ss app "
                      "running?); trying again every 0.4 s at most");
  EXPECT_THAT(m[2], MatchesRegex(link.uri + kBack));
  EXPECT_GE(link.source->stats().failed_attempts, 2);  // attempts at 0.05, 0.15 and 0.35 s
}

TEST(LiveLink, GivesUpAfterTheGiveUpTime) {
  LiveLinkOptions options = FastLink();
  options.give_up_after_s = 0.3;
  Link link("live_give_up", "restart:5s:after=2", options);
  link.ExpectFrames(2);
  EXPECT_FALSE(link.source->Next());
  EXPECT_EQ(link.source->failure(), link.uri + ": gave up after 0.3 s without frames");
}

TEST(LiveLink, RefusesAnotherDevice) {
  testing::Hl2ssTestRecording other("live_other_cal", Hl2ssDepthProfile::kSame, 1);
  std::vector<std::uint8_t> calibration = ReadHl2ssCalibrationAsMode2(other.dir.path());
  calibration[1000] ^= 0xFF;  // another headset's calibration
  Link link("live_other", "drop:after=2", FastLink(), calibration);
  link.ExpectFrames(2);
  EXPECT_FALSE(link.source->Next());
  EXPECT_EQ(link.source->failure(),
            link.uri +
                ": the device that answered is not the one navigation started with (its AHAT "
                "calibration differs); stopped: restart tofnav navigate to use it");
}

TEST(LiveLink, DamagedPacketIsReportedAndStopEndsTheWait) {
  // A server that answers the configuration with an impossible payload size.
  SocketFd listener = ListenTcp("127.0.0.1", 0);
  const int port = LocalPort(listener);
  std::thread server([&] {
    const SocketFd client(::accept(listener.get(), nullptr, nullptr));
    std::vector<std::uint8_t> config(26);  // 10 + 16 bytes: one encoder option
    ReadExact(client, config, "<test server>", "configuration");
    std::array<std::uint8_t, kHl2ssPacketHeaderBytes> header{};
    header.fill(0xFF);
    WriteAll(client, header, "<test server>");
  });
  std::atomic<bool> stop{false};
  std::vector<std::string> messages;
  LiveHl2ssSource source(
      {"127.0.0.1", port}, testing::Hl2ssTestConfig(Hl2ssDepthProfile::kSame), FastLink(), {},
      [&](const LinkReport& r) {
        if (!r.message.empty()) messages.push_back(r.message);
        stop = true;  // the user pressed Ctrl-C
      },
      &stop);
  EXPECT_FALSE(source.Next());
  server.join();
  EXPECT_TRUE(source.failure().empty());  // stopped, not failed
  ASSERT_EQ(messages.size(), 1u);
  EXPECT_EQ(messages[0], "hl2ss://127.0.0.1:" + std::to_string(port) +
                             ": the headset sent a damaged packet (payload size 4294967295 "
                             "exceeds the limit 16777216 (stream out of sync)) after 0 frames; "
                             "reconnecting");
}

TEST(LiveLink, NoStreamStateContinuesTheLastFrame) {
  NavigationState last;
  last.timestamp_s = 10.0;
  last.status = NavigationStatus::kTracking;
  last.reference_age_s = 0.0;
  last.active_trajectory = 1;
  last.instrument_status = ToolStatus::kOk;
  last.world_from_image = Rigid3d();
  const NavigationState s = NoStreamState(last, 1.5);
  EXPECT_EQ(s.status, NavigationStatus::kNoStream);
  EXPECT_DOUBLE_EQ(s.timestamp_s, 11.5);
  EXPECT_DOUBLE_EQ(s.stream_down_s, 1.5);
  EXPECT_DOUBLE_EQ(s.reference_age_s, 1.5);
  EXPECT_EQ(s.active_trajectory, 1);
  EXPECT_EQ(s.instrument_status, ToolStatus::kOutOfView);
  EXPECT_FALSE(s.world_from_image);  // no pose while the stream is down
}

}  // namespace
}  // namespace tofnav
