// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/stream/frame_rate_monitor.hpp"

#include <gtest/gtest.h>

namespace tofnav {
namespace {

TEST(FrameRateMonitor, SaysLowRateWithinOnePointFiveSecondsOfADropTo5Hz) {
  FrameRateMonitor monitor;
  double t = 0.0;
  FrameRateMonitor::Reading reading;
  for (int i = 0; i < 90; ++i, t += 1.0 / 45.0) reading = monitor.Update(t);  // 2 s at 45 Hz
  EXPECT_FALSE(reading.low_rate);
  EXPECT_NEAR(reading.rate_hz, 45.0, 0.5);  // tolerance: one frame in the window
  const double drop_s = t - 1.0 / 45.0;     // the last 45 Hz frame
  double low_at_s = -1.0;
  for (int i = 0; i < 15; ++i) {
    t += 0.2;
    reading = monitor.Update(t);
    if (reading.low_rate && low_at_s < 0.0) low_at_s = t;
  }
  ASSERT_GT(low_at_s, 0.0);
  // The line: LOW_RATE within 1.5 s of the drop (here the first 5 Hz frame after 1 s).
  EXPECT_LE(low_at_s - drop_s, 1.5);
  EXPECT_GE(low_at_s - drop_s, 1.0);
  EXPECT_NEAR(reading.rate_hz, 5.0, 0.01);
  // Back to 45 Hz: cleared at the first short interval.
  reading = monitor.Update(t + 1.0 / 45.0);
  EXPECT_FALSE(reading.low_rate);
}

TEST(FrameRateMonitor, ABriefGapIsNotLowRate) {
  FrameRateMonitor monitor;
  double t = 0.0;
  for (int i = 0; i < 45; ++i, t += 1.0 / 45.0) monitor.Update(t);
  EXPECT_FALSE(monitor.Update(t + 0.9).low_rate);  // one 900 ms gap (a stall), then 45 Hz
  EXPECT_FALSE(monitor.Update(t + 0.9 + 1.0 / 45.0).low_rate);
}

}  // namespace
}  // namespace tofnav
