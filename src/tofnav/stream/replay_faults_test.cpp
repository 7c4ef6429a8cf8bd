// SPDX-License-Identifier: BSD-3-Clause
// The replay server's fault list and schedule: parsing, periodic, once, and drawn faults.
#include "tofnav/stream/replay_faults.hpp"

#include <gtest/gtest.h>

#include "tofnav/core/require.hpp"

namespace tofnav {
namespace {

TEST(ReplayFaults, ParsesEveryKindAndParameter) {
  const std::vector<ReplayFault> faults = ParseReplayFaults(
      "drop:every=20s,stall:2s,reset,truncate:after=40,restart:500ms:at=5s,stall");
  const std::vector<ReplayFault> want = {
      {.kind = ReplayFaultKind::kDrop, .every_s = 20.0},
      {.kind = ReplayFaultKind::kStall, .duration_s = 2.0},
      {.kind = ReplayFaultKind::kReset},
      {.kind = ReplayFaultKind::kTruncate, .after_packets = 40},
      {.kind = ReplayFaultKind::kRestart, .duration_s = 0.5, .at_s = 5.0},
      {.kind = ReplayFaultKind::kStall, .duration_s = 2.0},  // the default stall
  };
  EXPECT_EQ(faults, want);
}

TEST(ReplayFaults, RefusesBadItemsByName) {
  const auto message = [](const std::string& text) {
    try {
      ParseReplayFaults(text);
    } catch (const PreconditionError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message("drop,explode"),
            "--faults item 'explode': unknown fault (drop, reset, stall, truncate, restart)");
  EXPECT_EQ(message("stall:2"), "--faults item 'stall:2': '2' is not a duration (2s, 500ms)");
  EXPECT_EQ(message("drop:3s"), "--faults item 'drop:3s': only stall and restart take a duration");
  EXPECT_EQ(message("reset:when=3s"), "--faults item 'reset:when=3s': unknown parameter 'when'");
  EXPECT_EQ(message("drop:after=x"), "--faults item 'drop:after=x': after= takes a packet count");
}

TEST(ReplayFaults, PeriodicFaultsCountFromTheEndOfTheLast) {
  ReplayFaultSchedule schedule({.faults = ParseReplayFaults("stall:2s:every=10s")});
  EXPECT_FALSE(schedule.Due(9.9, 0));
  EXPECT_TRUE(schedule.Due(10.0, 0));
  EXPECT_FALSE(schedule.Due(21.9, 0));  // 10 s after the stall's end
  EXPECT_TRUE(schedule.Due(22.0, 0));
}

TEST(ReplayFaults, OnceFaultsFireOnce) {
  ReplayFaultSchedule schedule({.faults = ParseReplayFaults("drop:after=40,reset:at=5s")});
  EXPECT_FALSE(schedule.Due(0.0, 39));
  EXPECT_EQ(schedule.Due(0.0, 40)->kind, ReplayFaultKind::kDrop);
  EXPECT_FALSE(schedule.Due(1.0, 41));
  EXPECT_EQ(schedule.Due(5.0, 41)->kind, ReplayFaultKind::kReset);
  EXPECT_FALSE(schedule.Due(100.0, 1000));
}

TEST(ReplayFaults, DrawnFaultsComeAtTheMeanIntervalAndRepeatWithTheSeed) {
  const ReplayFaultPlan plan{.faults = ParseReplayFaults("drop,reset"), .mean_interval_s = 20.0};
  ReplayFaultSchedule schedule(plan), again(plan);
  int drops = 0, resets = 0;
  for (int i = 0; i < 40000; ++i) {  // 2000 s in steps of 50 ms
    const std::optional<ReplayFault> f = schedule.Due(0.05 * i, 0);
    const std::optional<ReplayFault> g = again.Due(0.05 * i, 0);
    ASSERT_EQ(f.has_value(), g.has_value()) << "same seed, same schedule";
    if (f) ++(f->kind == ReplayFaultKind::kDrop ? drops : resets);
  }
  // 100 expected; intervals uniform in 10..30 s: sd of the count about 3, so +-10 is > 3 sd.
  constexpr int kExpected = 100, kTolerance = 10;
  EXPECT_NEAR(drops + resets, kExpected, kTolerance);
  EXPECT_GT(drops, 30);  // both kinds drawn (binomial 100, 1/2: 30 is 4 sd below)
  EXPECT_GT(resets, 30);
}

}  // namespace
}  // namespace tofnav
