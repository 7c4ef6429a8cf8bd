// SPDX-License-Identifier: BSD-3-Clause
// hl2ss replay server: Mode-2 blob or recorded packets, paced by timestamps, one client a time.
#include "tofnav/stream/hl2ss_replay_server.hpp"

#include <poll.h>
#include <sys/socket.h>

#include <array>
#include <chrono>
#include <cstring>

#include "tofnav/core/require.hpp"
#include "tofnav/io/hl2ss_calibration.hpp"
#include "tofnav/io/hl2ss_format.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/sensor/ahat_frame.hpp"
#include "tofnav/stream/hl2ss_client.hpp"

namespace tofnav {

void Hl2ssReplayOptions::Check() const {
  Require(port >= 0 && port <= 65535, "Hl2ssReplayOptions.port must be in 0..65535");
  Require(timeout_s > 0.0, "Hl2ssReplayOptions.timeout_s must be > 0");
}

Hl2ssReplayServer::Hl2ssReplayServer(const std::filesystem::path& recording,
                                     const std::filesystem::path& calibration,
                                     const Hl2ssReplayOptions& options)
    : options_(options), recording_(recording), file_(recording) {
  options_.Check();
  calibration_blob_ = ReadHl2ssCalibrationAsMode2(calibration);
  listener_ = ListenTcp(options_.bind_address, options_.port);
  port_ = LocalPort(listener_);
  thread_ = std::thread([this] { Run(); });
}

Hl2ssReplayServer::~Hl2ssReplayServer() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

Hl2ssReplayStats Hl2ssReplayServer::stats() const {
  const std::lock_guard lock(mutex_);
  return stats_;
}

void Hl2ssReplayServer::Run() {
  while (!stop_) {
    pollfd p{listener_.get(), POLLIN, 0};
    if (::poll(&p, 1, 100) <= 0) continue;
    const SocketFd client(::accept4(listener_.get(), nullptr, nullptr, SOCK_CLOEXEC));
    if (!client.valid()) continue;
    SetNoDelay(client);
    SetTimeouts(client, options_.timeout_s);
    {
      const std::lock_guard lock(mutex_);
      ++stats_.connections;
    }
    try {
      Serve(client);
    } catch (const IoError&) {
      // The client went away or sent garbage: serve the next one.
    }
  }
}

void Hl2ssReplayServer::Serve(const SocketFd& client) {
  const std::string source = "hl2ss replay client";
  std::array<std::uint8_t, 1> mode{};
  if (!ReadExact(client, mode, source, "mode")) return;
  if (mode[0] == 2) {
    WriteAll(client, calibration_blob_, source);
    const std::lock_guard lock(mutex_);
    ++stats_.calibrations_sent;
    return;
  }
  // The rest of the configuration: divisor .. n_options, then 16 bytes per option.
  std::vector<std::uint8_t> config(10);
  config[0] = mode[0];
  if (!ReadExact(client, std::span(config).subspan(1), source, "configuration")) return;
  config.resize(10 + std::size_t{16} * config[9]);
  if (!ReadExact(client, std::span(config).subspan(10), source, "encoder options")) return;
  const Hl2ssAhatConfig requested = DecodeHl2ssAhatConfig(config, source);
  const Hl2ssAhatConfig& recorded = recording_.config();
  if (requested.profile_z != recorded.profile_z || requested.profile_ab != recorded.profile_ab ||
      requested.mode > recorded.mode) {
    const std::lock_guard lock(mutex_);
    ++stats_.refused;
    return;  // no transcoding: close
  }
  {
    const std::lock_guard lock(mutex_);
    ++stats_.streams;
  }
  Stream(client, requested);
}

void Hl2ssReplayServer::Stream(const SocketFd& client, const Hl2ssAhatConfig& requested) {
  const std::string source = "hl2ss replay client";
  const std::uint64_t pose_bytes = recording_.config().mode == 1 ? kHl2ssPoseBytes : 0;
  const std::uint64_t keep_pose = requested.mode == 1 ? pose_bytes : 0;
  std::vector<std::uint8_t> packet;
  // Each loop continues the timeline one frame period after the last frame, so timestamps keep
  // increasing (trackers and filters need time order).
  const std::size_t frames = recording_.frame_count();
  const std::uint64_t span_ticks =
      frames < 2
          ? 222222
          : (recording_.host_ticks(frames - 1) - recording_.host_ticks(0)) * frames / (frames - 1);
  std::uint64_t shift_ticks = 0;
  do {
    const auto start = std::chrono::steady_clock::now();
    for (std::size_t i = 0; i < recording_.frame_count() && !stop_; i += requested.divisor) {
      const std::uint64_t offset = recording_.packet_offset(i);
      packet.resize(kHl2ssPacketHeaderBytes);
      file_.ReadAt(offset, packet, "packet header");
      std::uint32_t payload_bytes;
      std::memcpy(&payload_bytes, packet.data() + 8, sizeof(payload_bytes));
      packet.resize(kHl2ssPacketHeaderBytes + payload_bytes + keep_pose);
      file_.ReadAt(offset + kHl2ssPacketHeaderBytes,
                   std::span(packet).subspan(kHl2ssPacketHeaderBytes), "packet");
      const std::uint64_t ticks = recording_.host_ticks(i) + shift_ticks;
      std::memcpy(packet.data(), &ticks, sizeof(ticks));
      if (options_.realtime) {
        const double offset_s =
            static_cast<double>(recording_.host_ticks(i) - recording_.host_ticks(0)) *
            kSecondsPerHostTick;
        std::this_thread::sleep_until(start + std::chrono::duration_cast<std::chrono::nanoseconds>(
                                                  std::chrono::duration<double>(offset_s)));
      }
      WriteAll(client, packet, source);
      const std::lock_guard lock(mutex_);
      ++stats_.packets_sent;
    }
    shift_ticks += span_ticks;
  } while (options_.loop && !stop_);
}

}  // namespace tofnav
