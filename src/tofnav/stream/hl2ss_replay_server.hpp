// SPDX-License-Identifier: BSD-3-Clause
// Loopback hl2ss AHAT server replaying a recording with the live protocol (ahat.md section 6).
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "tofnav/io/file.hpp"
#include "tofnav/io/hl2ss_recording.hpp"
#include "tofnav/stream/socket.hpp"

namespace tofnav {

struct Hl2ssReplayOptions {
  std::string bind_address = "127.0.0.1";
  int port = 3804;         // 0: ephemeral (tests)
  bool realtime = true;    // pace packets by their timestamps; false: as fast as the client reads
  bool loop = false;       // restart at the end instead of closing the stream
  double timeout_s = 5.0;  // send timeout to a client that stopped reading
  void Check() const;
};

struct Hl2ssReplayStats {
  std::uint64_t connections = 0;
  std::uint64_t calibrations_sent = 0;
  std::uint64_t streams = 0;  // mode 0/1 requests served
  std::uint64_t refused = 0;  // bad or mismatched configuration
  std::uint64_t packets_sent = 0;
};

/// Serves one client at a time, like the device: a first byte 2 gets the Mode-2 calibration blob
/// (the folder's own bytes) and the connection closes; otherwise the rest of the configuration
/// is read and the recorded packets are streamed in file framing. Only the recorded profile is
/// served (no transcoding): a request with another depth or AB profile, or mode 1 from a mode-0
/// recording, is refused by closing. Mode 0 from a mode-1 recording drops the poses.
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

 private:
  void Run();
  void Serve(const SocketFd& client);
  void Stream(const SocketFd& client, const Hl2ssAhatConfig& requested);

  Hl2ssReplayOptions options_;
  Hl2ssRecording recording_;
  RandomAccessFile file_;
  std::vector<std::uint8_t> calibration_blob_;
  SocketFd listener_;
  int port_ = 0;
  mutable std::mutex mutex_;
  Hl2ssReplayStats stats_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace tofnav
