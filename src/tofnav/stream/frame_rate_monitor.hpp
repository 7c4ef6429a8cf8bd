// SPDX-License-Identifier: BSD-3-Clause
// The rate frames arrive at, and LOW_RATE: a real AHAT stream drops to about 5 Hz whenever the
// headset's hand tracker sees no hand (docs/navigation.md 4).
#pragma once

#include <deque>

namespace tofnav {

struct FrameRateOptions {
  double low_rate_hz = 15.0;  // an interval longer than 1 / low_rate_hz is a low-rate interval
  double low_for_s = 1.0;     // LOW_RATE once every interval has been long for this long
  double window_s = 1.0;      // the received rate: frames in the last window_s
  void Check() const;         // throws PreconditionError naming the bad field
};

/// Frame by frame: Update(t) with each frame's time stamp [s] (non-decreasing).
class FrameRateMonitor {
 public:
  explicit FrameRateMonitor(const FrameRateOptions& options = {});

  struct Reading {
    double rate_hz = 0.0;  // frames per second over the last window (0 before the second frame)
    bool low_rate = false;
  };
  Reading Update(double timestamp_s);

 private:
  FrameRateOptions options_;
  std::deque<double> window_;  // time stamps of the last window_s
  double low_since_s_ = -1.0;  // start of the current run of long intervals; < 0: none
};

}  // namespace tofnav
