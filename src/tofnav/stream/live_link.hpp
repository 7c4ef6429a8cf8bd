// SPDX-License-Identifier: BSD-3-Clause
// A live hl2ss link that survives the Wi-Fi: a closed, reset or stalled stream is a state, and
// the link reconnects with a bounded back-off (docs/navigation.md, "Live link").
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "tofnav/pipeline/navigator.hpp"
#include "tofnav/stream/hl2ss_client.hpp"

namespace tofnav {

struct LiveLinkOptions {
  double stall_timeout_s = 1.0;        // no packet for this long: the stream has stalled
  double first_backoff_s = 0.2;        // wait before the first reconnect, doubled per failure
  double max_backoff_s = 2.0;          // the longest wait between two attempts
  double calibration_timeout_s = 5.0;  // Mode-2 check of a reconnected device
  double give_up_after_s = 0.0;        // without frames this long: give up (0: never)
  double report_period_s = 0.1;        // while down, a LinkReport this often
  void Check() const;                  // throws PreconditionError naming the bad field
};

/// Counts of one session (the summary of `tofnav navigate --json`).
struct LiveLinkStats {
  std::int64_t disconnects = 0;      // closed, reset, broken off inside a packet, damaged
  std::int64_t stalls = 0;           // no packet for stall_timeout_s
  std::int64_t reconnects = 0;       // streams back (a frame after a fault)
  std::int64_t failed_attempts = 0;  // reconnect attempts that gave no frame
  double down_s = 0.0;               // time without frames, from the last frame before a fault
  double longest_down_s = 0.0;
  std::int64_t dropped_frames = 0;  // H26x units that did not decode (and those up to a key)
};

/// What the link tells the user: on every change (`message` set) and every report_period_s
/// while down (`message` empty).
struct LinkReport {
  bool up = true;
  bool changed = false;  // went down or came back with this report
  double down_s = 0.0;   // since the last frame arrived
  std::string message;   // one line: the peer, what happened, what it means
};

/// Frames from a live hl2ss AHAT stream. A fault (closed, reset, stalled, broken-off or damaged
/// stream) is reported, the socket closed, and the link reconnects after first_backoff_s,
/// doubling to max_backoff_s, re-sending the configuration; with `device_calibration` (the
/// Mode-2 bytes navigation started with) each reconnect first checks that the device sends the
/// same bytes. Single-threaded: reports are made from inside Next().
class LiveHl2ssSource : public FrameSource {
 public:
  using OnReport = std::function<void(const LinkReport&)>;
  /// Connects once (NetworkError when that fails: a wrong address is not a fault to wait out).
  LiveHl2ssSource(const Hl2ssEndpoint& endpoint, const Hl2ssAhatConfig& config,
                  const LiveLinkOptions& options,
                  std::optional<std::vector<std::uint8_t>> device_calibration = {},
                  OnReport on_report = {}, const std::atomic<bool>* stop = nullptr);
  ~LiveHl2ssSource() override;

  /// The next frame, reconnecting as long as it takes. nullopt only when `stop` became true, or
  /// the link ended for good: given up, or another device answered (then `failure()` says why).
  std::optional<AhatFrame> Next() override;
  std::string description() const override;
  /// The counts so far; down_s includes the current outage.
  LiveLinkStats stats() const;
  /// Why Next() ended without a stop request; empty otherwise.
  const std::string& failure() const { return failure_; }

 private:
  using Clock = std::chrono::steady_clock;
  void Back();
  void GoDown(const std::string& what, bool stalled);
  bool Reconnect();
  bool Wait(double seconds);
  void AttemptFailed(NetworkFailure failure, const std::string& detail);
  double DownS() const;
  void Report(const LinkReport& report);
  void CountDroppedFrames();

  Hl2ssEndpoint endpoint_;
  Hl2ssAhatConfig config_;
  LiveLinkOptions options_;
  std::optional<std::vector<std::uint8_t>> device_calibration_;
  OnReport on_report_;
  const std::atomic<bool>* stop_ = nullptr;
  std::unique_ptr<Hl2ssAhatClient> client_;
  std::int64_t client_dropped_ = 0;  // client_->dropped_frames() already counted
  bool up_ = true;
  std::int64_t frames_on_connection_ = 0;
  double backoff_s_ = 0.0;
  Clock::time_point last_frame_at_;
  Clock::time_point last_report_at_;
  std::vector<NetworkFailure> reported_failures_;  // attempt failures said in this outage
  LiveLinkStats stats_;
  std::string failure_;
};

/// The state published between frames while the link is down: status kNoStream, no pose, the
/// last frame's trajectory, its time and reference age advanced by `down_s`.
NavigationState NoStreamState(const NavigationState& last, double down_s);

}  // namespace tofnav
