// SPDX-License-Identifier: BSD-3-Clause
// Loopback hl2ss AHAT server replaying a recording with the live protocol (docs/ahat.md section 6).
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <mutex>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "tofnav/io/file.hpp"
#include "tofnav/recording/hl2ss_recording.hpp"
#include "tofnav/stream/replay_faults.hpp"
#include "tofnav/stream/socket.hpp"

namespace tofnav {

/// Something the server did, for the user of `tofnav serve` (called on the server's thread).
struct ReplayEvent {
  double elapsed_s = 0.0;  // since the server started
  std::string text;        // "fault 3: stall for 2.0 s after 412 packets on this stream"
};

struct Hl2ssReplayOptions {
  std::string bind_address = "127.0.0.1";
  int port = 3804;       // 0: ephemeral (tests)
  bool realtime = true;  // pace packets by their timestamps; false: as fast as the client reads
  /// Restart at the end instead of closing the stream. A looped stream is one timeline, like a
  /// camera that keeps running: a new connection goes on where it stands (realtime: at the
  /// frame due now), and time stamps keep increasing.
  bool loop = false;
  double timeout_s = 5.0;  // send timeout to a client that stopped reading
  ReplayFaultPlan faults;  // none by default
  std::function<void(const ReplayEvent&)> on_event;
  void Check() const;
};

struct Hl2ssReplayStats {
  std::uint64_t connections = 0;
  std::uint64_t calibrations_sent = 0;
  std::uint64_t streams = 0;  // mode 0/1 requests served
  std::uint64_t refused = 0;  // bad or mismatched configuration
  std::uint64_t packets_sent = 0;
  std::uint64_t faults = 0;  // injected
};

/// Serves one client at a time, like the device: a first byte 2 gets the Mode-2 calibration blob
/// (the folder's own bytes) and the connection closes; otherwise the rest of the configuration
/// is read and the recorded packets are streamed in file framing. A RAW recording is also served
/// in any other profile, encoded per connection as the headset does (H.264/H.265 at the bitrate
/// and GOP the client asks for); a request for another profile of an H26x recording, or mode 1
/// from a mode-0 recording, is refused by closing. Mode 0 from a mode-1 recording drops the poses.
/// Faults of `options.faults` are injected between packets of a stream (replay_faults.hpp).
class Hl2ssReplayServer {
 public:
  /// Opens the recording (hl2ss .bin) and the calibration folder, binds and starts; IoError.
  Hl2ssReplayServer(const std::filesystem::path& recording,
                    const std::filesystem::path& calibration, const Hl2ssReplayOptions& options);
  ~Hl2ssReplayServer();
  Hl2ssReplayServer(const Hl2ssReplayServer&) = delete;
  Hl2ssReplayServer& operator=(const Hl2ssReplayServer&) = delete;

  int port() const { return port_; }
  Hl2ssReplayStats stats() const;
  /// The time stamp [s] of the first recorded frame, sent when the server started (looped and
  /// real time: frame time minus this equals time since then, up to the network's delay).
  double first_timestamp_s() const;

 private:
  using Clock = std::chrono::steady_clock;
  void Run();
  void Serve(const SocketFd& client);
  /// Streams the recorded packets (`as_recorded`) or frames encoded for `requested`.
  void Stream(const SocketFd& client, const Hl2ssAhatConfig& requested, bool as_recorded);
  /// Injects `fault`; true when the stream must end.
  bool Inject(const ReplayFault& fault, const SocketFd& client,
              std::span<const std::uint8_t> packet, std::uint64_t sent_on_stream);
  std::uint64_t Ticks(std::uint64_t index) const;  // of a frame of the looped timeline
  Clock::time_point Due(std::uint64_t index) const;
  void Event(const std::string& text);
  bool SleepFor(double seconds);  // false when stopped meanwhile

  Hl2ssReplayOptions options_;
  Hl2ssRecording recording_;
  RandomAccessFile file_;
  std::vector<std::uint8_t> calibration_blob_;
  SocketFd listener_;
  int port_ = 0;
  mutable std::mutex mutex_;
  Hl2ssReplayStats stats_;
  ReplayFaultSchedule schedule_;
  Clock::time_point started_;
  Clock::time_point origin_;      // when frame 0 of the timeline is due
  std::uint64_t next_index_ = 0;  // of the looped timeline
  double restart_s_ = 0.0;        // a restart fault pending: stop listening this long
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace tofnav
