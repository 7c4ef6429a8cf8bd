// SPDX-License-Identifier: BSD-3-Clause
// HeadsetDisplay against the fake remote scene: what a wearer would see, frame by frame.
#include "tofnav/stream/headset_display.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <mutex>
#include <numbers>
#include <random>
#include <thread>

#include "tofnav/pipeline/guidance.hpp"
#include "tofnav/stream_testing/fake_remote_scene_server.hpp"

namespace tofnav {
namespace {

constexpr double kFloatMm = 1e-3;  // float32 metres on the wire
constexpr double kWait_s = 5.0;    // generous: ASan builds are slow

std::vector<Trajectory> Plan() {
  return {{"kocher_right", {-30.0, 40.0, 70.0}, {-5.0, 10.0, 5.0}},
          {"kocher_left", {30.0, 40.0, 70.0}, {5.0, 10.0, 5.0}}};
}

Rigid3d WorldFromImage(double shift_mm, double turn_rad) {
  return {Eigen::Quaterniond(
              Eigen::AngleAxisd(0.4 + turn_rad, Eigen::Vector3d(1, 2, 0.5).normalized())),
          Eigen::Vector3d(100.0 + shift_mm, 1400.0, -350.0)};
}

// A tracked frame; with `tip_offset`, an instrument whose tip lies `tip_offset` (in world, from
// 10 mm before the entry on the planned line) and whose axis is turned by `tilt_rad`.
NavigationState Tracked(const Rigid3d& world_from_image,
                        std::optional<Eigen::Vector3d> tip_offset = std::nullopt,
                        double tilt_rad = 0.0) {
  NavigationState s;
  s.status = NavigationStatus::kTracking;
  s.reference_age_s = 0.0;
  s.world_from_rig = Rigid3d(Eigen::Quaterniond::Identity(), {0.0, 1600.0, 300.0});
  s.world_from_image = world_from_image;
  for (const Trajectory& t : Plan()) {
    s.plan.push_back({world_from_image * t.entry_lps_mm, world_from_image * t.target_lps_mm,
                      t.entry_lps_mm, t.target_lps_mm});
  }
  if (tip_offset) {
    const PlacedTrajectory& t = s.plan.front();
    const Eigen::Vector3d u = (t.target_in_world - t.entry_in_world).normalized();
    s.tip_in_world = t.entry_in_world - 10.0 * u + *tip_offset;
    s.instrument_axis_in_world = Eigen::AngleAxisd(tilt_rad, u.unitOrthogonal()) * u;
    s.guidance = ComputeGuidance(*s.tip_in_world, *s.instrument_axis_in_world, t.entry_in_world,
                                 t.target_in_world);
  }
  return s;
}

NavigationState Lost(double age_s) {
  NavigationState s;
  s.status = NavigationStatus::kReferenceLost;
  s.reference_age_s = age_s;
  return s;
}

// The fake scene's object of display slot `slot` (objects are created in slot order).
const FakeSceneObject& Slot(const FakeRemoteScene& scene, std::size_t slot) {
  const std::size_t slots = HeadsetSlotCount(Plan().size());
  return scene.objects.at(scene.created[scene.created.size() - slots + slot]);
}

// What was spoken, without the empty `say` that probes the app's speech at each connect.
std::vector<std::string> Words(const FakeRemoteScene& scene) {
  std::vector<std::string> words;
  for (const std::string& w : scene.spoken) {
    if (!w.empty()) words.push_back(w);
  }
  return words;
}

// Shows `state` and waits until the fake headset has it: the scene it then holds.
FakeRemoteScene Show(HeadsetDisplay& display, const FakeRemoteSceneServer& server,
                     const NavigationState& state) {
  display.Update(state);
  EXPECT_TRUE(display.WaitUntilHandled(kWait_s));
  return server.scene();
}

HeadsetDisplayOptions Options(const FakeRemoteSceneServer& server) {
  HeadsetDisplayOptions o;
  o.port = server.port();
  o.speech_interval_s = 0.0;
  o.reconnect_interval_s = 0.05;
  o.expire_after_s = 60.0;   // the watchdog has its own test; slow (ASan) runs must not trip it
  o.io_timeout_s = kWait_s;  // nor a slow answer of the fake server
  return o;
}

TEST(HeadsetDisplay, PathEndPointsFollowThePlanEveryFrame) {
  // Issue 17: the displayed path equals the planned target and the extended entry within the
  // send threshold (0.1 mm) plus float32 rounding, in every frame.
  constexpr double kTolMm = 0.1 + kFloatMm;
  FakeRemoteSceneServer server;
  HeadsetDisplay display(Plan(), Options(server));
  std::mt19937 rng(5);
  std::normal_distribution<double> jitter(0.0, 0.3);
  for (int frame = 0; frame < 40; ++frame) {
    const NavigationState s = Tracked(WorldFromImage(jitter(rng), 0.002 * jitter(rng)));
    const FakeRemoteScene scene = Show(display, server, s);
    for (std::size_t i = 0; i < 2; ++i) {
      const PlacedTrajectory& t = s.plan[i];
      const Eigen::Vector3d out = (t.entry_in_world - t.target_in_world).normalized();
      const FakeSceneObject& path = Slot(scene, 3 * i + 2);
      ASSERT_TRUE(path.active);
      EXPECT_EQ(path.primitive, UnityPrimitive::kCylinder);
      const auto [bottom, top] = WorldCylinderEnds(path.transform);
      EXPECT_LT((bottom - t.target_in_world).norm(), kTolMm) << "frame " << frame;
      EXPECT_LT((top - (t.entry_in_world + 30.0 * out)).norm(), kTolMm) << "frame " << frame;
      const FakeSceneObject& entry = Slot(scene, 3 * i);
      EXPECT_LT((WorldFromUnityPoint(entry.transform.position_m.cast<double>()) - t.entry_in_world)
                    .norm(),
                kTolMm);
    }
    EXPECT_FALSE(Slot(scene, InstrumentAxisSlot(2)).active);  // no instrument
  }
  EXPECT_EQ(server.stats().rejected, 0u);
}

TEST(HeadsetDisplay, SmallMovesAreNotSent) {
  FakeRemoteSceneServer server;
  HeadsetDisplay display(Plan(), Options(server));
  display.Update(Tracked(WorldFromImage(0.0, 0.0)));
  display.Update(Tracked(WorldFromImage(0.0, 0.0)));
  ASSERT_TRUE(display.WaitUntilHandled(kWait_s));
  display.Update(Tracked(WorldFromImage(0.05, 0.0)));  // below 0.1 mm
  ASSERT_TRUE(display.WaitUntilHandled(kWait_s));
  const std::uint64_t lists = display.stats().display_lists;
  EXPECT_EQ(lists, 1u);
  display.Update(Tracked(WorldFromImage(0.3, 0.0)));
  ASSERT_TRUE(display.WaitUntilHandled(kWait_s));
  EXPECT_EQ(display.stats().display_lists, lists + 1);
}

TEST(HeadsetDisplay, ColoursTextAndSpeechFollowTheInstrument) {
  FakeRemoteSceneServer server;
  HeadsetDisplay display(Plan(), Options(server));
  const Rigid3d pose = WorldFromImage(0.0, 0.0);
  const auto show = [&](const NavigationState& s) { return Show(display, server, s); };
  FakeRemoteScene scene = show(Tracked(pose, Eigen::Vector3d::Zero()));
  const FakeSceneObject& tip = Slot(scene, InstrumentTipSlot(2));
  EXPECT_TRUE(tip.active);
  EXPECT_GT(tip.colour.g, 0.8f);  // green: on the line, along it
  EXPECT_NE(Slot(scene, TextPanelSlot(2)).text.find("tip-entry 10.0 mm"), std::string::npos);
  EXPECT_LT(Slot(scene, 3).colour.a, 0.5f);  // the other trajectory, dimmed
  EXPECT_EQ(Words(scene), (std::vector<std::string>{"on target"}));
  scene = show(Tracked(pose, Eigen::Vector3d::Zero()));  // still on target: not said again
  EXPECT_EQ(Words(scene).size(), 1u);
  const Eigen::Vector3d u =
      (pose.rotation * (Plan()[0].target_lps_mm - Plan()[0].entry_lps_mm)).normalized();
  scene = show(Tracked(pose, 3.0 * u.unitOrthogonal()));  // 3 mm off the line: amber
  EXPECT_GT(Slot(scene, InstrumentTipSlot(2)).colour.r, 0.9f);
  EXPECT_LT(Slot(scene, InstrumentTipSlot(2)).colour.g, 0.8f);
  EXPECT_GT(Slot(scene, 2).colour.r, 0.9f);  // the active path takes the state colour
  scene = show(Tracked(pose, Eigen::Vector3d::Zero(), 0.07));  // 4 deg tilt: amber
  EXPECT_LT(Slot(scene, InstrumentTipSlot(2)).colour.g, 0.8f);
  EXPECT_NE(Slot(scene, TextPanelSlot(2)).text.find("angle 4.0 deg"), std::string::npos);
  scene = show(Tracked(pose, Eigen::Vector3d::Zero()));
  EXPECT_EQ(Words(scene).size(), 2u);  // back on target
  scene = show(Tracked(pose));         // instrument gone: grey, hidden axis
  EXPECT_FALSE(Slot(scene, InstrumentTipSlot(2)).active);
  EXPECT_NEAR(Slot(scene, 2).colour.r, 0.6f, 1e-6f);
}

// On target, but the reference is SETTLING (one frame's orientation, not yet averaged): grey,
// the panel says so, nothing is spoken; once settled it turns green and is said.
TEST(HeadsetDisplay, ASettlingReferenceClaimsNothing) {
  FakeRemoteSceneServer server;
  HeadsetDisplay display(Plan(), Options(server));
  NavigationState settling = Tracked(WorldFromImage(0.0, 0.0), Eigen::Vector3d::Zero());
  settling.reference_rotation_sd_rad = 0.52 * std::numbers::pi / 180.0;
  settling.reference_settling = true;
  FakeRemoteScene scene = Show(display, server, settling);
  EXPECT_TRUE(Slot(scene, InstrumentTipSlot(2)).active);
  EXPECT_NEAR(Slot(scene, InstrumentTipSlot(2)).colour.g, 0.6f, 1e-6f);  // grey, not green
  EXPECT_NEAR(Slot(scene, 2).colour.g, 0.6f, 1e-6f);
  EXPECT_EQ(Slot(scene, TextPanelSlot(2)).text.rfind("SETTLING 0.5 deg\n", 0), 0u);
  EXPECT_TRUE(Words(scene).empty());
  settling.reference_settling = false;  // now settled
  scene = Show(display, server, settling);
  EXPECT_GT(Slot(scene, InstrumentTipSlot(2)).colour.g, 0.8f);
  EXPECT_EQ(Slot(scene, TextPanelSlot(2)).text.find("SETTLING"), std::string::npos);
  EXPECT_EQ(Words(scene), (std::vector<std::string>{"on target"}));
}

TEST(HeadsetDisplay, HologramsHideWhenTheReferenceIsLostAndReturnOnlyFresh) {
  FakeRemoteSceneServer server;
  HeadsetDisplay display(Plan(), Options(server));
  const auto active_count = [&] {
    EXPECT_TRUE(display.WaitUntilHandled(kWait_s));
    int n = 0;
    for (const auto& [key, o] : server.scene().objects) n += o.active ? 1 : 0;
    return n;
  };
  display.Update(Tracked(WorldFromImage(0.0, 0.0)));
  EXPECT_EQ(active_count(), 7);  // 2 x (entry, target, path) + text
  NavigationState holding = Tracked(WorldFromImage(0.0, 0.0));
  holding.status = NavigationStatus::kHolding;
  holding.reference_age_s = 0.08;  // held, still within 100 ms
  display.Update(holding);
  EXPECT_EQ(active_count(), 7);
  display.Update(Lost(0.12));  // the first frame past 100 ms
  EXPECT_EQ(active_count(), 0);
  display.Update(Lost(0.2));
  EXPECT_EQ(active_count(), 0);
  EXPECT_EQ(Words(server.scene()), (std::vector<std::string>{"reference lost"}));
  display.Update(Tracked(WorldFromImage(0.0, 0.0)));
  EXPECT_EQ(active_count(), 7);
}

// Issue 37: when the updates stop (a stalled link or navigation loop) the panel's tick stops
// within 0.2 s: the whole scene, panel included, hides.
TEST(HeadsetDisplay, NoUpdateForLongerThanThePoseAgeHidesTheScene) {
  constexpr double kStopWithinS = 0.2;
  FakeRemoteSceneServer server;
  std::mutex mutex;
  std::vector<std::chrono::steady_clock::time_point> lists;
  server.SetOnDisplayList([&](const FakeRemoteScene&) {
    const std::lock_guard lock(mutex);
    lists.push_back(std::chrono::steady_clock::now());
  });
  HeadsetDisplayOptions o = Options(server);
  o.expire_after_s = 0.1;
  HeadsetDisplay display(Plan(), o);
  display.Update(Tracked(WorldFromImage(0.0, 0.0)));
  ASSERT_TRUE(display.WaitUntilHandled(kWait_s));
  ASSERT_TRUE(server.WaitForDisplayLists(2, kWait_s));  // shown, then hidden by the watchdog
  for (const auto& [key, object] : server.scene().objects) EXPECT_FALSE(object.active);
  EXPECT_EQ(display.stats().expired, 1u);
  const std::lock_guard lock(mutex);
  ASSERT_GE(lists.size(), 2u);
  const double stopped_after_s = std::chrono::duration<double>(lists[1] - lists[0]).count();
  EXPECT_LE(stopped_after_s, kStopWithinS);
  std::printf("the panel hid %.0f ms after the last update\n", 1e3 * stopped_after_s);
}

TEST(HeadsetDisplay, StalledOrDroppedHeadsetLosesUpdatesAndReconnects) {
  FakeRemoteSceneServer server;
  HeadsetDisplayOptions o = Options(server);
  o.io_timeout_s = 0.5;  // a stalled server costs this per attempt
  HeadsetDisplay display(Plan(), o);
  display.Update(Tracked(WorldFromImage(0.0, 0.0)));
  ASSERT_TRUE(display.WaitUntilHandled(kWait_s));
  server.SetStalled(true);
  for (int i = 0; i < 50; ++i) display.Update(Tracked(WorldFromImage(i, 0.0)));  // never waits
  ASSERT_TRUE(display.WaitUntilHandled(kWait_s));
  EXPECT_GE(display.stats().disconnects, 1u);
  EXPECT_GE(display.stats().dropped, 1u);
  server.SetStalled(false);
  server.DropClient();
  const NavigationState last = Tracked(WorldFromImage(7.0, 0.0));
  for (int i = 0; i < 200 && !display.stats().connected; ++i) {
    display.Update(last);
    ASSERT_TRUE(display.WaitUntilHandled(kWait_s));
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  display.Update(last);
  ASSERT_TRUE(display.WaitUntilHandled(kWait_s));
  EXPECT_GE(display.stats().connections, 2u);
  const auto [bottom, top] = WorldCylinderEnds(Slot(server.scene(), 2).transform);
  EXPECT_LT((bottom - last.plan[0].target_in_world).norm(), 0.1 + kFloatMm);
}

TEST(HeadsetDisplay, CloseRemovesTheHolograms) {
  FakeRemoteSceneServer server;
  {
    HeadsetDisplay display(Plan(), Options(server));
    display.Update(Tracked(WorldFromImage(0.0, 0.0)));
    ASSERT_TRUE(display.WaitUntilHandled(kWait_s));
    EXPECT_EQ(server.scene().objects.size(), HeadsetSlotCount(2));
  }
  EXPECT_TRUE(server.scene().objects.empty());
}

TEST(HeadsetDisplay, AbsentHeadsetNeverBlocksUpdates) {
  HeadsetDisplayOptions o;
  o.port = ClosedLoopbackPort();
  HeadsetDisplay display(Plan(), o);
  for (int i = 0; i < 100; ++i) display.Update(Tracked(WorldFromImage(i, 0.0)));
  ASSERT_TRUE(display.WaitUntilHandled(kWait_s));
  EXPECT_FALSE(display.stats().connected);
  EXPECT_GE(display.stats().connect_failures, 1u);
  EXPECT_EQ(display.stats().updates, 100u);
}

// The real plugin runs one command per Unity frame outside a display list: a connect of
// 3n + 5 separate commands took 0.53 s for nine trajectories (issue 37). Connecting now sends
// the whole first scene in one display list, so the wearer sees it complete in one frame.
TEST(HeadsetDisplay, ConnectShowsTheWholeFirstSceneInOnePluginFrame) {
  FakeRemoteSceneServer server(0, {.frame_rate_hz = 60.0});
  HeadsetDisplay display(Plan(), Options(server));
  display.Update(Tracked(WorldFromImage(0.0, 0.0), Eigen::Vector3d(1.0, 0.0, 0.0)));
  ASSERT_TRUE(display.WaitUntilHandled(kWait_s));
  ASSERT_TRUE(server.WaitForDisplayLists(1, kWait_s));
  const FakeRemoteScene scene = server.scene();
  const FakeRemoteSceneStats stats = server.stats();
  EXPECT_EQ(scene.display_lists, 1u);                             // connect and scene together
  EXPECT_EQ(scene.frame - stats.connection_first_frame + 1, 1u);  // in one plugin frame
  std::size_t active = 0;
  for (const auto& [key, object] : scene.objects) active += object.active ? 1 : 0;
  EXPECT_GE(active, 3u);  // two paths and the panel at least
  EXPECT_EQ(scene.objects.size(), HeadsetSlotCount(Plan().size()));
  EXPECT_EQ(display.stats().dropped, 0u);
  EXPECT_EQ(display.stats().connections, 1u);
}

// Issue 37: the panel carries a tick that changes at >= 2 Hz while fresh poses are shown and
// stops with the updates, so that a frozen scene is seen to be frozen.
TEST(HeadsetDisplay, ThePanelTicksWhileLiveAndStopsWithTheUpdates) {
  FakeRemoteSceneServer server;
  HeadsetDisplay display(Plan(), Options(server));
  std::vector<std::string> texts;
  for (int k = 0; k < 45; ++k) {  // one second at 45 Hz
    NavigationState s = Tracked(WorldFromImage(0.0, 0.0));
    s.timestamp_s = 10.0 + k / 45.0;
    display.Update(s);
    ASSERT_TRUE(display.WaitUntilHandled(kWait_s));
    texts.push_back(Slot(server.scene(), TextPanelSlot(2)).text);
  }
  std::size_t changes = 0;
  for (std::size_t k = 1; k < texts.size(); ++k) changes += texts[k] != texts[k - 1] ? 1 : 0;
  EXPECT_GE(changes, 3u);  // four quarter seconds in one second: >= 2 Hz
  EXPECT_NE(texts.back().find("live 10.75 s"), std::string::npos) << texts.back();
}

struct Notices {
  std::mutex mutex;
  std::vector<std::string> lines;
  void Add(const std::string& line) {
    const std::lock_guard lock(mutex);
    lines.push_back(line);
  }
  std::vector<std::string> Get() {
    const std::lock_guard lock(mutex);
    return lines;
  }
};

// Issue 37: an app without text-to-speech never answers `say`; probed once at connect, speech
// goes off with one line and the holograms go on.
TEST(HeadsetDisplay, AnAppWithoutSpeechGetsTextOnlyAndOneLine) {
  FakeRemoteSceneServer server(0, {.say_answers = false});
  Notices notices;
  HeadsetDisplayOptions options = Options(server);
  options.io_timeout_s = 0.3;
  options.on_notice = [&](const std::string& line) { notices.Add(line); };
  HeadsetDisplay display(Plan(), options);
  for (int k = 0; k < 4; ++k) {  // connect + probe, then reconnect without speech
    display.Update(Tracked(WorldFromImage(0.1 * k, 0.0), Eigen::Vector3d(0.5, 0.0, 0.0)));
    ASSERT_TRUE(display.WaitUntilHandled(kWait_s));
  }
  EXPECT_EQ(notices.Get(),
            (std::vector<std::string>{"the headset app does not answer 'say' (no text-to-speech "
                                      "component): speech is off, the panel's text only"}));
  const HeadsetDisplayStats stats = display.stats();
  EXPECT_FALSE(stats.speech_available);
  EXPECT_EQ(stats.connections, 2u);  // the probe's connection is dropped once, not every time
  EXPECT_TRUE(stats.connected);
  EXPECT_TRUE(Slot(server.scene(), 2).active);  // the path is shown
  EXPECT_EQ(stats.spoken, 0u);
}

// Issue 37: the plugin serves one client; a second one is told so in one line, not silently
// retried.
TEST(HeadsetDisplay, ASecondClientIsReportedInOneLine) {
  FakeRemoteSceneServer server;
  RemoteSceneClient other("127.0.0.1", server.port(), kWait_s);  // e.g. hl2ss's viewer
  RemoteSceneCommands c;
  c.CreateText();
  ASSERT_EQ(other.Push(c).size(), 1u);
  Notices notices;
  HeadsetDisplayOptions options = Options(server);
  options.io_timeout_s = 0.2;
  options.on_notice = [&](const std::string& line) { notices.Add(line); };
  HeadsetDisplay display(Plan(), options);
  for (int k = 0; k < 5; ++k) {
    display.Update(Tracked(WorldFromImage(0.0, 0.0)));
    ASSERT_TRUE(display.WaitUntilHandled(kWait_s));
    std::this_thread::sleep_for(std::chrono::milliseconds(60));  // past the reconnect interval
  }
  EXPECT_EQ(notices.Get(),
            (std::vector<std::string>{
                "the headset accepted the connection but answered nothing within 0.2 s: another "
                "client (a second tofnav, hl2ss's viewer) holds its remote scene; retrying after "
                "0.05 s, then ever less often (at most every 8 s)"}));
  EXPECT_GE(display.stats().connect_failures, 2u);
  EXPECT_FALSE(display.stats().connected);
}

}  // namespace
}  // namespace tofnav
