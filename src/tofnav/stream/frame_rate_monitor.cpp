// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/stream/frame_rate_monitor.hpp"

#include <cmath>

#include "tofnav/core/require.hpp"

namespace tofnav {

void FrameRateOptions::Check() const {
  Require(std::isfinite(low_rate_hz) && low_rate_hz > 0.0,
          "FrameRateOptions.low_rate_hz must be > 0");
  Require(std::isfinite(low_for_s) && low_for_s >= 0.0, "FrameRateOptions.low_for_s must be >= 0");
  Require(std::isfinite(window_s) && window_s > 0.0, "FrameRateOptions.window_s must be > 0");
}

FrameRateMonitor::FrameRateMonitor(const FrameRateOptions& options) : options_(options) {
  options_.Check();
}

FrameRateMonitor::Reading FrameRateMonitor::Update(double timestamp_s) {
  Reading reading;
  if (!window_.empty()) {
    const double previous_s = window_.back();
    if (timestamp_s - previous_s > 1.0 / options_.low_rate_hz) {
      if (low_since_s_ < 0.0) low_since_s_ = previous_s;  // the run started with that frame
    } else {
      low_since_s_ = -1.0;
    }
  }
  window_.push_back(timestamp_s);
  while (window_.size() > 2 && window_.front() < timestamp_s - options_.window_s) {
    window_.pop_front();
  }
  if (window_.size() >= 2) {
    const double span_s = window_.back() - window_.front();
    reading.rate_hz = span_s > 0.0 ? static_cast<double>(window_.size() - 1) / span_s : 0.0;
  }
  reading.low_rate = low_since_s_ >= 0.0 && timestamp_s - low_since_s_ >= options_.low_for_s;
  return reading;
}

}  // namespace tofnav
