// SPDX-License-Identifier: BSD-3-Clause
// Fault list parsing and the schedule of the replay server's faults.
#include "tofnav/stream/replay_faults.hpp"

#include <cmath>
#include <sstream>

#include "tofnav/core/require.hpp"

namespace tofnav {
namespace {

/// A bad --faults item: a user's input, so the message names the item, not a source line.
[[noreturn]] void Bad(const std::string& item, const std::string& why) {
  throw PreconditionError("--faults item '" + item + "': " + why);
}

std::vector<std::string> Split(const std::string& text, char separator) {
  std::vector<std::string> parts;
  std::istringstream in(text);
  for (std::string part; std::getline(in, part, separator);) parts.push_back(part);
  return parts;
}

/// "2s", "2.5s", "500ms" -> seconds; nullopt when `text` is not a duration.
std::optional<double> ParseDuration(const std::string& text) {
  const bool ms = text.ends_with("ms");
  if (!ms && !text.ends_with("s")) return std::nullopt;
  const std::string number = text.substr(0, text.size() - (ms ? 2 : 1));
  std::size_t used = 0;
  double value = 0.0;
  try {
    value = std::stod(number, &used);
  } catch (const std::exception&) {
    return std::nullopt;
  }
  if (used != number.size() || !std::isfinite(value)) return std::nullopt;
  return ms ? value * 1e-3 : value;
}

ReplayFault ParseItem(const std::string& item) {
  const std::vector<std::string> parts = Split(item, ':');
  if (parts.empty()) Bad(item, "empty");
  ReplayFault fault;
  const std::string kinds[] = {"drop", "reset", "stall", "truncate", "restart"};
  std::size_t k = 0;
  while (k < std::size(kinds) && kinds[k] != parts[0]) ++k;
  if (k == std::size(kinds)) Bad(item, "unknown fault (drop, reset, stall, truncate, restart)");
  fault.kind = static_cast<ReplayFaultKind>(k);
  const bool timed =
      fault.kind == ReplayFaultKind::kStall || fault.kind == ReplayFaultKind::kRestart;
  if (timed) fault.duration_s = fault.kind == ReplayFaultKind::kStall ? 2.0 : 3.0;
  for (std::size_t i = 1; i < parts.size(); ++i) {
    const std::string& p = parts[i];
    const std::size_t equals = p.find('=');
    const std::string key = equals == std::string::npos ? "" : p.substr(0, equals);
    const std::string value = equals == std::string::npos ? p : p.substr(equals + 1);
    if (key == "after") {
      if (value.empty() || value.size() > 18 ||
          value.find_first_not_of("0123456789") != std::string::npos) {
        Bad(item, "after= takes a packet count");
      }
      fault.after_packets = std::stoull(value);
      continue;
    }
    if (!key.empty() && key != "every" && key != "at") Bad(item, "unknown parameter '" + key + "'");
    const std::optional<double> seconds = ParseDuration(value);
    if (!seconds || *seconds < 0.0) Bad(item, "'" + value + "' is not a duration (2s, 500ms)");
    if (key == "every") {
      if (*seconds <= 0.0) Bad(item, "every= must be > 0");
      fault.every_s = seconds;
    } else if (key == "at") {
      fault.at_s = seconds;
    } else {
      if (!timed) Bad(item, "only stall and restart take a duration");
      fault.duration_s = *seconds;
    }
  }
  return fault;
}

}  // namespace

void ReplayFaultPlan::Check() const {
  Require(mean_interval_s > 0.0, "ReplayFaultPlan.mean_interval_s must be > 0");
  for (const ReplayFault& f : faults) {
    Require(f.duration_s >= 0.0, "ReplayFaultPlan.faults: duration_s must be >= 0");
    Require(!f.every_s || *f.every_s > 0.0, "ReplayFaultPlan.faults: every_s must be > 0");
  }
}

std::vector<ReplayFault> ParseReplayFaults(const std::string& text) {
  std::vector<ReplayFault> faults;
  for (const std::string& item : Split(text, ',')) faults.push_back(ParseItem(item));
  return faults;
}

ReplayFaultSchedule::ReplayFaultSchedule(const ReplayFaultPlan& plan)
    : plan_(plan), done_(plan.faults.size(), false), rng_(plan.seed) {
  plan_.Check();
  std::uniform_real_distribution<double> jitter(0.5, 1.5);
  for (std::size_t i = 0; i < plan_.faults.size(); ++i) {
    const ReplayFault& f = plan_.faults[i];
    next_s_.push_back(f.every_s ? *f.every_s : f.at_s.value_or(0.0));
    if (!f.every_s && !f.at_s && !f.after_packets) drawn_.push_back(i);
  }
  next_drawn_s_ = jitter(rng_) * plan_.mean_interval_s;
}

std::optional<ReplayFault> ReplayFaultSchedule::Due(double elapsed_s, std::uint64_t packets) {
  for (std::size_t i = 0; i < plan_.faults.size(); ++i) {
    const ReplayFault& f = plan_.faults[i];
    if (f.every_s && elapsed_s >= next_s_[i]) {
      next_s_[i] = elapsed_s + f.duration_s + *f.every_s;
      return f;
    }
    const bool once_due =
        (f.at_s && elapsed_s >= *f.at_s) || (f.after_packets && packets >= *f.after_packets);
    if (!done_[i] && once_due) {
      done_[i] = true;
      return f;
    }
  }
  if (drawn_.empty() || elapsed_s < next_drawn_s_) return std::nullopt;
  std::uniform_int_distribution<std::size_t> pick(0, drawn_.size() - 1);
  const ReplayFault& f = plan_.faults[drawn_[pick(rng_)]];
  std::uniform_real_distribution<double> jitter(0.5, 1.5);
  next_drawn_s_ = elapsed_s + f.duration_s + jitter(rng_) * plan_.mean_interval_s;
  return f;
}

}  // namespace tofnav
