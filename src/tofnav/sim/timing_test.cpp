// SPDX-License-Identifier: BSD-3-Clause
// Frame slots at 45 Hz in 100 ns ticks, frame-drop statistics, SLAM jitter statistics.
#include "tofnav/sim/timing.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "matchers.hpp"
#include "tofnav/core/require.hpp"

namespace tofnav::sim {
namespace {

TEST(SlotTicks, FortyFiveHertzInHundredNanosecondTicks) {
  const FrameTimingOptions options;
  EXPECT_EQ(SlotTicks(options, 0), options.start_ticks);
  EXPECT_EQ(SlotTicks(options, 1) - SlotTicks(options, 0), 222'222u);      // 22.2222 ms, rounded
  EXPECT_EQ(SlotTicks(options, 45) - SlotTicks(options, 0), 10'000'000u);  // exactly 1 s
  EXPECT_EQ(SlotTicks(options, 45 * 3600) - SlotTicks(options, 0), 36'000'000'000u);
}

TEST(FrameClock, WithoutDropsEverySlotIsAFrame) {
  FrameClock clock(FrameTimingOptions{}, 3);
  for (std::int64_t slot = 0; slot < 100; ++slot) ASSERT_EQ(clock.NextSlot(), slot);
  EXPECT_EQ(clock.dropped_slots(), 0);
}

TEST(FrameClock, AStrideKeepsEveryNthSlotAndCountsTheRestAsDropped) {
  FrameTimingOptions options;
  options.slot_stride = 7;
  FrameClock clock(options, 3);
  for (std::int64_t k = 0; k < 50; ++k) ASSERT_EQ(clock.NextSlot(), 7 * k);
  EXPECT_EQ(clock.dropped_slots(), 49 * 6);  // the slots between the 50 kept ones
  // With drops, a dropped run skips whole strides: every slot stays a multiple of 7 and the
  // slots without a frame are exactly the gaps.
  options.drop_probability = 0.2;
  FrameClock dropping(options, 5);
  std::int64_t slot = 0;
  for (int i = 0; i < 1000; ++i) {
    slot = dropping.NextSlot();
    ASSERT_EQ(slot % 7, 0);
  }
  EXPECT_EQ(dropping.dropped_slots(), slot + 1 - 1000);
  options.slot_stride = 0;
  EXPECT_THROW(options.Check(), PreconditionError);
}

TEST(FrameClock, WithoutAHandInViewTheCameraRunsAtItsLowRate) {
  FrameTimingOptions options;
  options.no_hand_rate_hz = 5.0;  // 45 / 5: one frame every 9 slots without a hand
  FrameClock clock(options, 3);
  const auto hand = [](std::int64_t slot) { return slot >= 90 && slot < 180; };
  std::vector<std::int64_t> slots;
  while (slots.empty() || slots.back() < 270) slots.push_back(clock.NextSlot(hand));
  for (std::size_t i = 1; i < slots.size(); ++i) {
    const std::int64_t gap = slots[i] - slots[i - 1];
    if (hand(slots[i])) {
      EXPECT_EQ(gap, slots[i] == 90 ? 9 : 1) << slots[i];  // 45 Hz as soon as the hand is seen
    } else {
      EXPECT_EQ(gap, 9) << slots[i];
    }
  }
  // 10 frames in the first 90 slots, 90 with the hand, 11 after it (slots 188-278); every
  // other slot up to the last frame's is skipped.
  EXPECT_EQ(slots.size(), 111u);
  EXPECT_EQ(slots.back(), 278);
  EXPECT_EQ(clock.throttled_slots(), 279 - 111);
  EXPECT_EQ(clock.dropped_slots(), clock.throttled_slots());
}

TEST(FrameClock, DropsFollowTheGeometricBurstModel) {
  FrameTimingOptions options;
  options.drop_probability = 0.1;
  options.mean_drop_slots = 3.0;
  FrameClock clock(options, 11);
  constexpr int kFrames = 20'000;
  std::int64_t last = clock.NextSlot();
  EXPECT_EQ(last, 0);
  int bursts = 0;
  for (int i = 1; i < kFrames; ++i) {
    const std::int64_t slot = clock.NextSlot();
    ASSERT_GT(slot, last);
    bursts += slot > last + 1 ? 1 : 0;
    last = slot;
  }
  // Expected: a burst after 10 % of the frames, 3 slots long on average. Binomial standard
  // errors are about 2 % and 1.5 % here; 10 % bounds cannot fail by chance.
  EXPECT_NEAR(static_cast<double>(bursts) / kFrames, 0.1, 0.01);
  EXPECT_NEAR(static_cast<double>(clock.dropped_slots()) / bursts, 3.0, 0.3);
  EXPECT_EQ(last, kFrames - 1 + clock.dropped_slots());
}

TEST(JitterPose, ZeroSigmaKeepsThePoseAndSigmaSetsTheSpread) {
  const Rigid3d pose(Eigen::Quaterniond(0.9, 0.1, 0.2, 0.3), {100.0, 200.0, 300.0});
  std::mt19937_64 rng(5);
  EXPECT_THAT(JitterPose(pose, {0.0, 0.0}, rng), RigidNear(pose, 1e-15, 1e-12));
  const SlamJitterOptions options{0.5, 1e-3};
  double sum_t2 = 0.0, sum_r2 = 0.0;
  constexpr int kSamples = 4000;
  for (int i = 0; i < kSamples; ++i) {
    const Rigid3d jittered = JitterPose(pose, options, rng);
    sum_t2 += (pose.Inverse() * jittered).translation.squaredNorm();
    sum_r2 += std::pow(RotationDistanceRad(pose, jittered), 2);
  }
  // Three axes each: E|t|^2 = 3 sigma_t^2, E angle^2 = 3 sigma_r^2; 4000 samples: +-4 %.
  EXPECT_NEAR(std::sqrt(sum_t2 / (3 * kSamples)), 0.5, 0.03);
  EXPECT_NEAR(std::sqrt(sum_r2 / (3 * kSamples)), 1e-3, 6e-5);
}

}  // namespace
}  // namespace tofnav::sim
