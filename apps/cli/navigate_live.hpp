// SPDX-License-Identifier: BSD-3-Clause
// The live-link side of `tofnav navigate`: the hl2ss source, its messages and its summary.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "tofnav/stream/live_link.hpp"

namespace tofnav {

/// Exit status of `navigate` when the live link gave up or another device answered.
constexpr int kExitGaveUp = 3;

/// The live source for `--profile` (any hl2ss profile, e.g. "zdepth+h265") at `bitrate_bps`
/// (unset: the hl2ss client's default for the profile), mode 1 (poses), GOP 45 for H26x.
std::unique_ptr<LiveHl2ssSource> MakeLiveSource(
    const Hl2ssEndpoint& endpoint, const Hl2ssStreamProfile& profile,
    std::optional<std::uint32_t> bitrate_bps, const LiveLinkOptions& options,
    std::optional<std::vector<std::uint8_t>> device_calibration, const std::atomic<bool>* stop,
    LiveHl2ssSource::OnReport on_report);

/// The one-line warning `navigate` prints for a SAME + H26x stream (lossy depth, half-resolution
/// AB), with what it costs tracking (docs/ahat.md 3.6.5).
std::string LossyDepthWarning(const Hl2ssStreamProfile& profile);

/// Prints a report's message as one line on stderr ("tofnav navigate: ..."), first clearing
/// the live status line when there is one.
void ReportLink(const LinkReport& report, bool status_line);

/// The "link" object of the --json summary.
nlohmann::ordered_json LinkSummary(const LiveLinkStats& stats);

}  // namespace tofnav
