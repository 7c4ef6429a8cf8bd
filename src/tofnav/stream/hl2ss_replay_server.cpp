// SPDX-License-Identifier: BSD-3-Clause
// hl2ss replay server: Mode-2 blob or recorded packets, paced by timestamps, one client a time,
// with injected faults.
#include "tofnav/stream/hl2ss_replay_server.hpp"

#include <poll.h>
#include <sys/socket.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <optional>

#include "tofnav/core/require.hpp"
#include "tofnav/io/io_error.hpp"
#include "tofnav/recording/hl2ss_calibration.hpp"
#include "tofnav/recording/hl2ss_format.hpp"
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
    : options_(options), recording_(recording), file_(recording), schedule_(options.faults) {
  options_.Check();
  calibration_blob_ = ReadHl2ssCalibrationAsMode2(calibration);
  listener_ = ListenTcp(options_.bind_address, options_.port);
  port_ = LocalPort(listener_);
  started_ = origin_ = Clock::now();
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

double Hl2ssReplayServer::first_timestamp_s() const {
  return recording_.frame_count() == 0
             ? 0.0
             : static_cast<double>(recording_.host_ticks(0)) * kSecondsPerHostTick;
}

void Hl2ssReplayServer::Run() {
  while (!stop_) {
    if (restart_s_ > 0.0) {  // a restart fault: the device's server is away for a while
      listener_.Close();
      const bool stopped = !SleepFor(restart_s_);
      restart_s_ = 0.0;
      if (stopped) return;
      listener_ = ListenTcp(options_.bind_address, port_);
      Event("listening again");
    }
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
    } catch (const IoError& e) {
      Event(std::string("client gone: ") + e.what());  // went away or sent garbage: serve the next
    }
  }
}

void Hl2ssReplayServer::Serve(const SocketFd& client) {
  const std::string source = "hl2ss replay client";
  std::array<std::uint8_t, 1> mode{};
  if (!ReadExact(client, mode, source, "mode")) return;
  if (mode[0] == 2) {
    WriteAll(client, calibration_blob_, source);
    {
      const std::lock_guard lock(mutex_);
      ++stats_.calibrations_sent;
    }
    Event("calibration sent (Mode 2)");
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
  const bool same_profile =
      requested.profile_z == recorded.profile_z && requested.profile_ab == recorded.profile_ab;
  // Another profile is encoded on the fly from a RAW recording, as the headset encodes what each
  // client asks for; a lossy recording is not re-encoded (its losses would add up).
  const bool can_transcode = recorded.profile_ab == Hl2ssVideoProfile::kRaw;
  if ((!same_profile && !can_transcode) || requested.mode > recorded.mode) {
    const std::lock_guard lock(mutex_);
    ++stats_.refused;
    return;  // close
  }
  std::uint64_t number = 0;
  {
    const std::lock_guard lock(mutex_);
    number = ++stats_.streams;
  }
  Event("stream " + std::to_string(number) + ": " + Hl2ssProfileName(requested) + " mode " +
        std::to_string(requested.mode) +
        (same_profile ? "" : ", encoded from the " + Hl2ssProfileName(recorded) + " recording"));
  Stream(client, requested, same_profile);
}

void Hl2ssReplayServer::Stream(const SocketFd& client, const Hl2ssAhatConfig& requested,
                               bool as_recorded) {
  const std::string source = "hl2ss replay client";
  const std::uint64_t pose_bytes = recording_.config().mode == 1 ? kHl2ssPoseBytes : 0;
  const std::uint64_t keep_pose = requested.mode == 1 ? pose_bytes : 0;
  const std::uint64_t frames = recording_.frame_count();
  if (frames == 0) return;
  if (!options_.loop) {  // a replay from the start
    next_index_ = 0;
    origin_ = Clock::now();
  }
  std::uint64_t sent_on_stream = 0;
  std::vector<std::uint8_t> packet;
  // A new encoder per connection, as the headset builds one (its stream starts with a key frame).
  std::optional<Hl2ssPacketEncoder> encoder;
  if (!as_recorded) encoder.emplace(requested);
  while (!stop_ && (options_.loop || next_index_ < frames)) {
    if (options_.realtime && options_.loop) {  // the camera kept running: the frame due now
      while (Due(next_index_ + requested.divisor) <= Clock::now()) next_index_ += requested.divisor;
    }
    const std::uint64_t ticks = Ticks(next_index_);
    if (encoder) {
      AhatFrame frame = recording_.ReadFrame(next_index_ % frames);
      frame.host_ticks = ticks;
      packet = encoder->Encode(frame);
    } else {
      const std::uint64_t offset = recording_.packet_offset(next_index_ % frames);
      packet.resize(kHl2ssPacketHeaderBytes);
      file_.ReadAt(offset, packet, "packet header");
      std::uint32_t payload_bytes;
      std::memcpy(&payload_bytes, packet.data() + 8, sizeof(payload_bytes));
      packet.resize(kHl2ssPacketHeaderBytes + payload_bytes + keep_pose);
      file_.ReadAt(offset + kHl2ssPacketHeaderBytes,
                   std::span(packet).subspan(kHl2ssPacketHeaderBytes), "packet");
      std::memcpy(packet.data(), &ticks, sizeof(ticks));
    }
    if (options_.realtime) std::this_thread::sleep_until(Due(next_index_));
    const double elapsed_s = std::chrono::duration<double>(Clock::now() - started_).count();
    if (const std::optional<ReplayFault> fault = schedule_.Due(elapsed_s, stats().packets_sent)) {
      if (Inject(*fault, client, packet, sent_on_stream)) return;
      continue;  // after a stall: the frame due now (looped) or this one, later
    }
    WriteAll(client, packet, source);
    next_index_ += requested.divisor;
    ++sent_on_stream;
    const std::lock_guard lock(mutex_);
    ++stats_.packets_sent;
  }
}

bool Hl2ssReplayServer::Inject(const ReplayFault& fault, const SocketFd& client,
                               std::span<const std::uint8_t> packet, std::uint64_t sent_on_stream) {
  std::uint64_t number = 0;
  {
    const std::lock_guard lock(mutex_);
    number = ++stats_.faults;
  }
  char text[160];
  const std::string name = "fault " + std::to_string(number) + ": ";
  const std::string after = " after " + std::to_string(sent_on_stream) + " packets on this stream";
  switch (fault.kind) {
    case ReplayFaultKind::kDrop:
      Event(name + "drop: closed the connection" + after);
      return true;
    case ReplayFaultKind::kReset:
      SetResetOnClose(client);
      Event(name + "reset: reset the connection" + after);
      return true;
    case ReplayFaultKind::kTruncate: {
      const std::size_t part =
          kHl2ssPacketHeaderBytes + (packet.size() - kHl2ssPacketHeaderBytes) / 2;
      std::snprintf(text, sizeof text, "truncate: sent %zu of %zu bytes of a packet, then closed",
                    part, packet.size());
      Event(name + text + after);
      WriteAll(client, packet.first(part), "hl2ss replay client");
      return true;
    }
    case ReplayFaultKind::kRestart:
      std::snprintf(text, sizeof text, "restart: closed and not listening for %.1f s",
                    fault.duration_s);
      Event(name + text + after);
      restart_s_ = fault.duration_s;
      return true;
    case ReplayFaultKind::kStall:
      std::snprintf(text, sizeof text, "stall: sending nothing for %.1f s", fault.duration_s);
      Event(name + text + after);
      if (!SleepFor(fault.duration_s)) return true;
      if (!options_.loop) {
        origin_ += std::chrono::duration_cast<Clock::duration>(
            std::chrono::duration<double>(fault.duration_s));
      }
      Event(name + "stall over, sending again");
      return false;
  }
  return true;
}

std::uint64_t Hl2ssReplayServer::Ticks(std::uint64_t index) const {
  // Each pass continues the timeline one mean frame period after the last frame, so time stamps
  // keep increasing (trackers and filters need time order).
  const std::uint64_t frames = recording_.frame_count();
  const std::uint64_t span_ticks =
      frames < 2
          ? 222222
          : (recording_.host_ticks(frames - 1) - recording_.host_ticks(0)) * frames / (frames - 1);
  return recording_.host_ticks(index % frames) + (index / frames) * span_ticks;
}

Hl2ssReplayServer::Clock::time_point Hl2ssReplayServer::Due(std::uint64_t index) const {
  const double offset_s =
      static_cast<double>(Ticks(index) - recording_.host_ticks(0)) * kSecondsPerHostTick;
  return origin_ +
         std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(offset_s));
}

void Hl2ssReplayServer::Event(const std::string& text) {
  if (options_.on_event) {
    options_.on_event({std::chrono::duration<double>(Clock::now() - started_).count(), text});
  }
}

bool Hl2ssReplayServer::SleepFor(double seconds) {
  const Clock::time_point until = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                                     std::chrono::duration<double>(seconds));
  while (!stop_ && Clock::now() < until) {
    std::this_thread::sleep_until(std::min(until, Clock::now() + std::chrono::milliseconds(20)));
  }
  return !stop_;
}

}  // namespace tofnav
