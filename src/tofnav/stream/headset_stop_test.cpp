// SPDX-License-Identifier: BSD-3-Clause
// What a supervisor leaves on the headset when navigation ended without clearing it (issue 37
// item 3): HeadsetDisplay's record of what is shown, and the "navigation stopped" panel.
#include "tofnav/stream/headset_stop.hpp"

#include <gtest/gtest.h>

#include <mutex>

#include "tofnav/io/io_error.hpp"
#include "tofnav/stream_testing/fake_remote_scene_server.hpp"

namespace tofnav {
namespace {

constexpr double kWaitS = 5.0;  // generous: sanitizer builds are slow

std::vector<Trajectory> OnePath() { return {{"kocher_right", {-30, 40, 70}, {-5, 10, 5}}}; }

NavigationState TrackedAt(double x_mm) {
  NavigationState s;
  s.status = NavigationStatus::kTracking;
  s.reference_age_s = 0.0;
  s.world_from_rig = Rigid3d(Eigen::Quaterniond::Identity(), {0.0, 1600.0, 300.0});
  s.world_from_image = Rigid3d(Eigen::Quaterniond::Identity(), {x_mm, 1400.0, -350.0});
  for (const Trajectory& t : OnePath()) {
    s.plan.push_back({*s.world_from_image * t.entry_lps_mm, *s.world_from_image * t.target_lps_mm,
                      t.entry_lps_mm, t.target_lps_mm});
  }
  return s;
}

struct ShownLog {
  std::mutex mutex;
  std::vector<HeadsetShown> reports;
  HeadsetShown Last() {
    const std::lock_guard lock(mutex);
    return reports.empty() ? HeadsetShown{} : reports.back();
  }
};

HeadsetDisplayOptions Options(int port, ShownLog& log) {
  HeadsetDisplayOptions o;
  o.port = port;
  o.expire_after_s = 60.0;  // no watchdog hide in slow runs
  o.io_timeout_s = kWaitS;
  o.on_shown = [&log](const HeadsetShown& s) {
    const std::lock_guard lock(log.mutex);
    log.reports.push_back(s);
  };
  return o;
}

// The display tells its supervisor what is left on the headset: holograms and the panel's place
// after every answered push, nothing once Close removed them.
TEST(HeadsetStop, TheDisplayReportsWhatTheHeadsetShowsUntilClose) {
  FakeRemoteSceneServer server;
  ShownLog log;
  HeadsetDisplay display(OnePath(), Options(server.port(), log));
  display.Update(TrackedAt(100.0));
  ASSERT_TRUE(display.WaitUntilHandled(kWaitS));
  const HeadsetShown shown = log.Last();
  EXPECT_TRUE(shown.anything);
  ASSERT_TRUE(shown.panel.has_value());
  const Hologram expected =
      ComposeHeadsetScene(TrackedAt(100.0), OnePath()).holograms[TextPanelSlot(1)];
  EXPECT_EQ(shown.panel->a_in_world, expected.a_in_world);  // exact: the panel as composed
  EXPECT_EQ(shown.panel->b_in_world, expected.b_in_world);
  display.Close();
  EXPECT_FALSE(log.Last().anything);
  EXPECT_TRUE(display.stats().cleared);
  EXPECT_TRUE(server.scene().objects.empty());
}

// A display whose headset went away before Close cannot clear it: the supervisor must.
TEST(HeadsetStop, ADisplayThatLostItsHeadsetIsNotCleared) {
  ShownLog log;
  auto server = std::make_unique<FakeRemoteSceneServer>();
  HeadsetDisplay display(OnePath(), Options(server->port(), log));
  display.Update(TrackedAt(100.0));
  ASSERT_TRUE(display.WaitUntilHandled(kWaitS));
  server.reset();  // the headset drops off the network
  display.Update(TrackedAt(110.0));
  ASSERT_TRUE(display.WaitUntilHandled(kWaitS));
  display.Close();
  EXPECT_FALSE(display.stats().cleared);
  EXPECT_TRUE(log.Last().anything);
}

// Everything goes; one red panel, where the guidance panel last stood, says why.
TEST(HeadsetStop, StoppedReplacesTheSceneByOneRedPanelInThePanelsPlace) {
  FakeRemoteSceneServer server(0, FakeRemoteSceneOptions{.frame_rate_hz = 60.0});
  ShownLog log;
  {
    HeadsetDisplay display(OnePath(), Options(server.port(), log));
    display.Update(TrackedAt(100.0));
    ASSERT_TRUE(display.WaitUntilHandled(kWaitS));
    ASSERT_EQ(server.scene().objects.size(), HeadsetSlotCount(1));
    const std::uint32_t panel_key = server.scene().created.back();
    const FakeSceneObject before = server.scene().objects.at(panel_key);
    const std::uint64_t lists = server.scene().display_lists;
    // While the display holds the plugin's one client slot nobody else can clear the headset:
    // the supervisor acts once the worker has gone.
    HeadsetDisplayOptions stop = Options(server.port(), log);
    stop.io_timeout_s = 0.2;
    EXPECT_THROW(ShowNavigationStopped(stop, log.Last().panel, "NAVIGATION STOPPED", 0.3), IoError);
    display.Close();
    ShowNavigationStopped(Options(server.port(), log), log.reports.front().panel,
                          "NAVIGATION STOPPED\n(tofnav ended: killed by signal 9)");
    ASSERT_TRUE(server.WaitForDisplayLists(lists + 2, kWaitS));
    const FakeRemoteScene scene = server.scene();
    ASSERT_EQ(scene.objects.size(), 1u);
    const FakeSceneObject& notice = scene.objects.begin()->second;
    EXPECT_TRUE(notice.is_text);
    EXPECT_TRUE(notice.active);
    EXPECT_EQ(notice.text, "NAVIGATION STOPPED\n(tofnav ended: killed by signal 9)");
    EXPECT_EQ(notice.colour, (Rgba{1.0f, 0.2f, 0.15f, 1.0f}));
    // Same place and facing as the guidance panel (float32 metres on the wire).
    EXPECT_LT((notice.transform.position_m - before.transform.position_m).norm(), 1e-6f);
    EXPECT_LT(notice.transform.rotation.angularDistance(before.transform.rotation), 1e-6f);
  }
}

// Never shown a panel (the reference never tracked): the scene is only emptied.
TEST(HeadsetStop, WithoutAPanelTheSceneIsOnlyEmptied) {
  FakeRemoteSceneServer server;
  {
    RemoteSceneClient earlier("127.0.0.1", server.port(), kWaitS);  // then gone
    RemoteSceneCommands c;
    c.CreatePrimitive(UnityPrimitive::kSphere);
    ASSERT_EQ(earlier.Push(c).size(), 1u);
  }
  ShownLog log;
  ShowNavigationStopped(Options(server.port(), log), std::nullopt, "NAVIGATION STOPPED");
  EXPECT_TRUE(server.scene().objects.empty());
}

// No headset: an error naming it, after the given time.
TEST(HeadsetStop, AnAbsentHeadsetIsAnErrorNamingIt) {
  const int port = ClosedLoopbackPort();
  ShownLog log;
  HeadsetDisplayOptions o = Options(port, log);
  o.io_timeout_s = 0.1;
  try {
    ShowNavigationStopped(o, std::nullopt, "NAVIGATION STOPPED", 0.2);
    FAIL() << "no error";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("tcp://127.0.0.1:" + std::to_string(port)),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace tofnav
