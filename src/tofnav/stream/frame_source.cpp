// SPDX-License-Identifier: BSD-3-Clause
// Recording replay, paced by the recorded timestamps when asked.
#include "tofnav/stream/frame_source.hpp"

#include <thread>
#include <utility>

#include "tofnav/core/require.hpp"
#include "tofnav/sensor/ahat_frame.hpp"

namespace tofnav {

RecordingFrameSource::RecordingFrameSource(std::unique_ptr<AhatRecording> recording, bool realtime)
    : recording_(std::move(recording)), realtime_(realtime) {
  Require(recording_ != nullptr, "RecordingFrameSource: no recording");
}

std::optional<AhatFrame> RecordingFrameSource::Next() {
  if (next_ >= recording_->frame_count()) return std::nullopt;
  if (realtime_) {
    if (next_ == 0) start_ = std::chrono::steady_clock::now();
    const double offset_s =
        static_cast<double>(recording_->host_ticks(next_) - recording_->host_ticks(0)) *
        kSecondsPerHostTick;
    std::this_thread::sleep_until(start_ + std::chrono::duration_cast<std::chrono::nanoseconds>(
                                               std::chrono::duration<double>(offset_s)));
  }
  return recording_->ReadFrame(next_++);
}

std::string RecordingFrameSource::description() const {
  return recording_->format() + ", " + std::to_string(recording_->frame_count()) + " frames" +
         (realtime_ ? ", real time" : "");
}

}  // namespace tofnav
