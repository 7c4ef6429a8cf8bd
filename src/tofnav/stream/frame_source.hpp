// SPDX-License-Identifier: BSD-3-Clause
// Where navigation frames come from: a recording (paced or as fast as possible) or a live hl2ss.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "tofnav/sensor/ahat_frame.hpp"
#include "tofnav/sensor/ahat_recording.hpp"

namespace tofnav {

/// A stream of AHAT frames in time order.
class FrameSource {
 public:
  virtual ~FrameSource() = default;
  /// The next frame; nullopt at the end of the stream. IoError on corrupt data or the network.
  virtual std::optional<AhatFrame> Next() = 0;
  virtual std::string description() const = 0;
};

struct ReplayOptions {
  bool realtime = false;  // pace by the recorded timestamps (not frame indices: rates vary)
  bool loop = false;      // restart at the end, timestamps shifted to keep increasing
};

/// Replays a recording. With `realtime`, Next() sleeps until the frame's time since the first
/// frame has passed on the steady clock.
class RecordingFrameSource : public FrameSource {
 public:
  RecordingFrameSource(std::unique_ptr<AhatRecording> recording, const ReplayOptions& options);
  std::optional<AhatFrame> Next() override;
  std::string description() const override;
  const AhatRecording& recording() const { return *recording_; }

 private:
  std::unique_ptr<AhatRecording> recording_;
  ReplayOptions options_;
  std::size_t next_ = 0;
  std::uint64_t shift_ticks_ = 0;  // added to the timestamps of the current pass
  std::chrono::steady_clock::time_point start_;
};

}  // namespace tofnav
