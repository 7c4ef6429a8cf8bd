// SPDX-License-Identifier: BSD-3-Clause
// Recording replay, paced by the recorded timestamps when asked.
#include "tofnav/stream/frame_source.hpp"

#include <thread>
#include <utility>

#include "tofnav/core/require.hpp"
#include "tofnav/sensor/ahat_frame.hpp"

namespace tofnav {

RecordingFrameSource::RecordingFrameSource(std::unique_ptr<AhatRecording> recording,
                                           const ReplayOptions& options)
    : recording_(std::move(recording)), options_(options) {
  Require(recording_ != nullptr, "RecordingFrameSource: no recording");
}

std::optional<AhatFrame> RecordingFrameSource::Next() {
  const std::size_t frames = recording_->frame_count();
  if (options_.loop && frames > 0 && next_ == frames) {
    // The next pass starts one mean frame period after the last frame.
    const std::uint64_t span = recording_->host_ticks(frames - 1) - recording_->host_ticks(0);
    shift_ticks_ += frames < 2 ? 222222 : span + span / (frames - 1);
    next_ = 0;
  }
  if (next_ >= frames) return std::nullopt;
  if (options_.realtime) {
    if (next_ == 0 && shift_ticks_ == 0) start_ = std::chrono::steady_clock::now();
    const double offset_s = static_cast<double>(recording_->host_ticks(next_) + shift_ticks_ -
                                                recording_->host_ticks(0)) *
                            kSecondsPerHostTick;
    std::this_thread::sleep_until(start_ + std::chrono::duration_cast<std::chrono::nanoseconds>(
                                               std::chrono::duration<double>(offset_s)));
  }
  AhatFrame frame = recording_->ReadFrame(next_++);
  frame.host_ticks += shift_ticks_;
  return frame;
}

std::string RecordingFrameSource::description() const {
  return recording_->format() + ", " + std::to_string(recording_->frame_count()) + " frames" +
         (options_.realtime ? ", real time" : "") + (options_.loop ? ", looped" : "");
}

}  // namespace tofnav
