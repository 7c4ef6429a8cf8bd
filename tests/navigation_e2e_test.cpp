// SPDX-License-Identifier: BSD-3-Clause
// Navigation end to end on evd-usecase: accuracy against truth (issue 8, acceptance line 4) and
// the loopback chain hl2ss replay server -> client -> Navigator -> OpenIGTLink -> 1.11 client.
#include <gtest/gtest.h>

#include <cstdio>
#include <map>
#include <mutex>
#include <numbers>
#include <thread>

#include "navigation_e2e_case.hpp"
#include "tofnav/core/units.hpp"
#include "tofnav/io/io_test_helpers.hpp"
#include "tofnav/pipeline/guidance.hpp"
#include "tofnav/recording/hl2ss_calibration.hpp"
#include "tofnav/recording/hl2ss_recording.hpp"
#include "tofnav/stream/hl2ss_client.hpp"
#include "tofnav/stream/hl2ss_replay_server.hpp"
#include "tofnav/stream/igtl_codec.hpp"
#include "tofnav/stream/igtl_test_client.hpp"
#include "tofnav/stream/navigation_messages.hpp"
#include "tofnav/stream/navigation_session.hpp"

namespace tofnav {
namespace {

struct Errors {
  std::vector<double> entry_ahat_mm, direction_deg, entry_world_mm;
  std::vector<double> guidance_entry_mm, guidance_angle_deg, guidance_depth_mm;
  void Print(const char* label) const {
    const auto line = [](const char* name, const std::vector<double>& v, const char* unit) {
      std::printf("  %-26s n=%5zu mean %.3f  median %.3f  p95 %.3f  max %.3f %s\n", name, v.size(),
                  testing::Mean(v), testing::Percentile(v, 0.5), testing::Percentile(v, 0.95),
                  testing::Percentile(v, 1.0), unit);
    };
    std::printf("%s\n", label);
    line("entry error (ahat)", entry_ahat_mm, "mm");
    line("entry error (world)", entry_world_mm, "mm");
    line("direction error", direction_deg, "deg");
    line("guidance tip->entry error", guidance_entry_mm, "mm");
    line("guidance angle error", guidance_angle_deg, "deg");
    line("guidance depth error", guidance_depth_mm, "mm");
  }
};

// Acceptance line 4: with the true tool_from_image, every trajectory's displayed entry point and
// direction against the truth, over all nine trajectories and every tracked frame.
TEST(NavigationE2E, EvdUseCaseEntryAndDirectionErrorsWithTrueRegistration) {
  constexpr double kMaxEntryMm = 1.0, kMaxDirectionDeg = 1.0;  // issue 8 acceptance
  // Per-frame tracking noise over a 150 mm lever: raw, the disc plates' tilt is 0.5-1 deg off
  // for a second at a time (docs/tracking.md 1), 1.3-2.6 mm at the entry (p95 1.81 mm on this
  // draw). The reference's orientation filtered in `world` takes that to p95 1.21 mm; 1.5 leaves
  // 25 % for the draw.
  constexpr double kMaxEntryP95Mm = 1.5;
  // ... and must beat the raw pose (--no-filter) on the same frames: mean 0.47 against 0.72 mm,
  // p95 1.21 against 1.81 mm; at most 0.8 of raw's mean and no worse a p95 leave room for the
  // draw while failing if the filter stopped averaging the tilt (docs/navigation.md 1).
  constexpr double kMaxMeanOfRaw = 0.8;
  constexpr double kMinTrackedFraction = 0.9;                   // the wearer looks away at times
  const testing::EvdCase c = testing::MakeEvdCase(240, false);  // joined headframe tools
  const testing::EvdCase g = testing::MakeEvdCase(240, true);   // left tool + "instrument"
  sim::Simulator simulator(c.scenario);
  Navigator navigator(simulator.camera(), c.navigation_case);
  NavigatorOptions options;
  options.instrument_axis_in_tool = testing::InstrumentAxisInTool(g);
  Navigator guide(simulator.camera(), g.navigation_case, options);
  NavigatorOptions raw_options;  // the ablation: each frame's raw reference pose
  raw_options.tracking.filter_enabled = false;
  Navigator raw(simulator.camera(), c.navigation_case, raw_options);
  const auto& plan = c.navigation_case.plan;
  const int patient = c.scenario.patient->object;
  Errors e;
  std::vector<double> raw_entry_ahat_mm;
  int frames = 0, tracked = 0;
  while (!simulator.done()) {
    const sim::SimulatedFrame f = simulator.Next();
    const NavigationState s = navigator.Process(f.render.frame);
    const NavigationState with_tool = guide.Process(f.render.frame);
    const NavigationState unfiltered = raw.Process(f.render.frame);
    ++frames;
    if (with_tool.guidance) {  // truth: tip 10 mm before entry 0 on the planned line, axis along
      const double length = (plan[0].target_lps_mm - plan[0].entry_lps_mm).norm();
      e.guidance_entry_mm.push_back(std::abs(with_tool.guidance->tip_to_entry_mm - 10.0));
      e.guidance_angle_deg.push_back(with_tool.guidance->angle_to_axis_rad * kRadToDeg);
      e.guidance_depth_mm.push_back(
          std::abs(with_tool.guidance->remaining_depth_mm - (10.0 + length)));
    }
    const Rigid3d ahat_from_image = f.ahat_from_objects[static_cast<std::size_t>(patient)];
    if (unfiltered.status == NavigationStatus::kTracking) {
      const Rigid3d est = *unfiltered.ahat_from_tool * c.tool_from_image;
      for (const Trajectory& t : plan) {
        raw_entry_ahat_mm.push_back(
            (est * t.entry_lps_mm - ahat_from_image * t.entry_lps_mm).norm());
      }
    }
    if (s.status != NavigationStatus::kTracking) continue;
    ++tracked;
    const Rigid3d world_from_image_true =
        f.world_from_rig_true * simulator.camera().rig_from_ahat() * ahat_from_image;
    const Rigid3d ahat_from_image_est = *s.ahat_from_tool * c.tool_from_image;
    for (const Trajectory& t : plan) {
      const Eigen::Vector3d d_true = ahat_from_image.rotation * (t.target_lps_mm - t.entry_lps_mm);
      const Eigen::Vector3d d_est =
          ahat_from_image_est.rotation * (t.target_lps_mm - t.entry_lps_mm);
      e.entry_ahat_mm.push_back(
          (ahat_from_image_est * t.entry_lps_mm - ahat_from_image * t.entry_lps_mm).norm());
      e.direction_deg.push_back(AngleBetweenRad(d_est, d_true) * kRadToDeg);
      e.entry_world_mm.push_back(
          (*s.world_from_image * t.entry_lps_mm - world_from_image_true * t.entry_lps_mm).norm());
    }
  }
  e.Print("evd-usecase, true tool_from_image, 9 trajectories:");
  std::printf("  tracked %d of %d frames\n", tracked, frames);
  std::printf(
      "  raw reference pose (--no-filter): entry error (ahat) n=%zu mean %.3f median %.3f "
      "p95 %.3f mm\n",
      raw_entry_ahat_mm.size(), testing::Mean(raw_entry_ahat_mm),
      testing::Percentile(raw_entry_ahat_mm, 0.5), testing::Percentile(raw_entry_ahat_mm, 0.95));
  EXPECT_LE(testing::Mean(e.entry_ahat_mm), kMaxMeanOfRaw * testing::Mean(raw_entry_ahat_mm));
  EXPECT_LE(testing::Percentile(e.entry_ahat_mm, 0.95),
            testing::Percentile(raw_entry_ahat_mm, 0.95));
  EXPECT_GE(tracked, kMinTrackedFraction * frames);
  EXPECT_LE(testing::Mean(e.entry_ahat_mm), kMaxEntryMm);
  EXPECT_LE(testing::Percentile(e.entry_ahat_mm, 0.5), kMaxEntryMm);
  EXPECT_LE(testing::Percentile(e.entry_ahat_mm, 0.95), kMaxEntryP95Mm);
  EXPECT_LE(testing::Mean(e.direction_deg), kMaxDirectionDeg);
  EXPECT_LE(testing::Percentile(e.direction_deg, 0.95), kMaxDirectionDeg);
  EXPECT_FALSE(e.guidance_entry_mm.empty());
}

// The whole live chain over sockets; acceptance line 1: the 1.11 client receives RasToWorld equal
// to the chain of the frame's poses within 1e-3 mm.
TEST(NavigationE2E, LoopbackHl2ssToOpenIgtlinkClient) {
  constexpr double kWireMm = 1e-3;  // float32 on the wire at ~2 m from the world origin
  const testing::EvdCase c = testing::MakeEvdCase(30, false);
  testing::TempDir dir("navigation_e2e");
  const std::filesystem::path recording = dir.path() / "rm_depth_ahat.bin";
  std::vector<sim::SimulatedFrame> truth;
  {
    sim::Simulator simulator(c.scenario);
    Hl2ssRecordingWriter writer(recording, {});
    while (!simulator.done()) {
      truth.push_back(simulator.Next());
      writer.Append(truth.back().render.frame);
    }
    writer.Close();
    WriteHl2ssCalibration(dir.path(), simulator.calibration());
  }
  Hl2ssReplayServer hl2ss(recording, dir.path(), {.port = 0, .realtime = false});
  const Hl2ssEndpoint endpoint{"127.0.0.1", hl2ss.port()};
  Navigator navigator(AhatCamera(DownloadHl2ssCalibration(endpoint)), c.navigation_case);
  IgtlServer igtl({.port = 0});
  SetNavigationGreetings(igtl, navigator);
  testing::IgtlTestClient client(igtl.port());
  ASSERT_TRUE(testing::WaitFor([&] { return igtl.stats().clients == 1; }));

  Hl2ssAhatConfig config;
  config.encoder_options = {{10, 1}};
  Hl2ssAhatClient source(endpoint, config);
  std::mutex mutex;
  std::map<std::uint64_t, Rigid3d> sent;  // IGTL time stamp -> world_from_image of the state
  std::vector<std::pair<std::uint64_t, Rigid3d>> received;
  std::thread reader([&] {
    while (auto m = client.Receive()) {
      if (m->device_name == "NavigationStatus" && m->text == "END") break;
      if (m->device_name == "RasToWorld") received.emplace_back(0, *m->transform);
    }
  });
  const NavigationSessionStats stats =
      RunNavigationSession(source, navigator, &igtl, [&](const NavigationState& s) {
        if (s.world_from_image) {
          const std::lock_guard lock(mutex);
          sent[sent.size()] = *s.world_from_image;
        }
      });
  igtl.Publish(EncodeIgtlMessage("STRING", "NavigationStatus", 0, IgtlStringContent("END")));
  reader.join();
  EXPECT_EQ(stats.frames, static_cast<std::int64_t>(truth.size()));
  ASSERT_EQ(received.size(), sent.size());
  ASSERT_GT(sent.size(), 0u);
  double worst_mm = 0.0;
  for (std::size_t i = 0; i < received.size(); ++i) {
    for (const Trajectory& t : c.navigation_case.plan) {  // points of the plan, in RAS
      const Eigen::Vector3d in_world = received[i].second * (RasFromImage() * t.target_lps_mm);
      worst_mm = std::max(worst_mm, (in_world - sent.at(i) * t.target_lps_mm).norm());
    }
  }
  std::printf("loopback: %zu RasToWorld received, worst plan-point difference %.2e mm\n",
              received.size(), worst_mm);
  EXPECT_LE(worst_mm, kWireMm);
  EXPECT_EQ(igtl.stats().messages_dropped, 0u);
}

}  // namespace
}  // namespace tofnav
