// SPDX-License-Identifier: BSD-3-Clause
// Faults the hl2ss replay server injects, so a live session can be rehearsed and tested without
// a headset (`tofnav serve --faults`, docs/navigation.md).
#pragma once

#include <cstdint>
#include <optional>
#include <random>
#include <string>
#include <vector>

namespace tofnav {

enum class ReplayFaultKind {
  kDrop,      // close the connection between two packets
  kReset,     // reset it (TCP RST)
  kStall,     // send nothing for duration_s, then go on on the same connection
  kTruncate,  // send part of a packet, then close
  kRestart,   // close the connection and stop listening for duration_s
};

struct ReplayFault {
  ReplayFaultKind kind = ReplayFaultKind::kDrop;
  double duration_s = 0.0;                     // kStall, kRestart only
  std::optional<double> every_s;               // periodic, from the server's start
  std::optional<double> at_s;                  // once, this long after the server started
  std::optional<std::uint64_t> after_packets;  // once, after this many packets (all streams)
  bool operator==(const ReplayFault&) const = default;
};

struct ReplayFaultPlan {
  /// Faults with neither every_s, at_s nor after_packets are drawn at random (uniformly among
  /// them), mean_interval_s apart on average (uniform in 0.5 to 1.5 times that).
  std::vector<ReplayFault> faults;
  double mean_interval_s = 20.0;
  std::uint64_t seed = 1;
  void Check() const;  // throws PreconditionError naming the bad field
};

/// Parses a comma-separated list of KIND[:PARAM...], PARAM one of DURATION (stall, restart;
/// default 2 s and 3 s), every=DURATION, at=DURATION or after=PACKETS; DURATION is a number
/// followed by "s" or "ms". Example: "drop:every=20s,stall:2s,reset,truncate,restart:3s".
/// Throws PreconditionError naming the bad item.
std::vector<ReplayFault> ParseReplayFaults(const std::string& text);

/// When the faults of a plan are due.
class ReplayFaultSchedule {
 public:
  explicit ReplayFaultSchedule(const ReplayFaultPlan& plan);
  /// The fault due `elapsed_s` after the server started, with `packets` sent so far (all
  /// streams), if any; at most one per call. The next periodic or random fault is counted from
  /// the end of this one.
  std::optional<ReplayFault> Due(double elapsed_s, std::uint64_t packets);

 private:
  ReplayFaultPlan plan_;
  std::vector<double> next_s_;  // per fault: its next time (periodic, once at a time)
  std::vector<bool> done_;      // per fault given once
  std::vector<std::size_t> drawn_;
  double next_drawn_s_ = 0.0;
  std::mt19937_64 rng_;
};

}  // namespace tofnav
