// SPDX-License-Identifier: BSD-3-Clause
// Where navigation frames come from: a recording (paced or as fast as possible) or a live hl2ss.
#pragma once

#include <chrono>
#include <cstddef>
#include <memory>
#include <optional>
#include <string>

#include "tofnav/io/ahat_recording.hpp"
#include "tofnav/sensor/ahat_frame.hpp"

namespace tofnav {

/// A stream of AHAT frames in time order.
class FrameSource {
 public:
  virtual ~FrameSource() = default;
  /// The next frame; nullopt at the end of the stream. IoError on corrupt data or the network.
  virtual std::optional<AhatFrame> Next() = 0;
  virtual std::string description() const = 0;
};

/// Replays a recording. With `realtime`, Next() sleeps until the frame's time since the first
/// frame (timestamps, not frame indices: AHAT rates vary) has passed on the steady clock.
class RecordingFrameSource : public FrameSource {
 public:
  RecordingFrameSource(std::unique_ptr<AhatRecording> recording, bool realtime);
  std::optional<AhatFrame> Next() override;
  std::string description() const override;
  const AhatRecording& recording() const { return *recording_; }

 private:
  std::unique_ptr<AhatRecording> recording_;
  bool realtime_ = false;
  std::size_t next_ = 0;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace tofnav
