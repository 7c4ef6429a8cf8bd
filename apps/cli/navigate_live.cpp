// SPDX-License-Identifier: BSD-3-Clause
// `tofnav navigate hl2ss://...`: configuration, link messages and counts (docs/navigation.md).
#include "navigate_live.hpp"

#include <cstdio>
#include <utility>

namespace tofnav {

std::unique_ptr<LiveHl2ssSource> MakeLiveSource(
    const Hl2ssEndpoint& endpoint, const std::string& profile, const LiveLinkOptions& options,
    std::optional<std::vector<std::uint8_t>> device_calibration, const std::atomic<bool>* stop,
    LiveHl2ssSource::OnReport on_report) {
  Hl2ssAhatConfig config;
  config.profile_z = profile == "zdepth" ? Hl2ssDepthProfile::kZdepth : Hl2ssDepthProfile::kSame;
  config.bitrate_bps = Hl2ssDefaultAhatBitrate(config.profile_z, Hl2ssVideoProfile::kRaw);
  config.encoder_options = {{10, 1}};
  return std::make_unique<LiveHl2ssSource>(endpoint, config, options, std::move(device_calibration),
                                           std::move(on_report), stop);
}

void ReportLink(const LinkReport& report, bool status_line) {
  if (report.message.empty()) return;
  std::fprintf(stderr, "%stofnav navigate: %s\n", status_line ? "\r\033[K" : "",
               report.message.c_str());
}

nlohmann::ordered_json LinkSummary(const LiveLinkStats& stats) {
  return {{"disconnects", stats.disconnects},       {"stalls", stats.stalls},
          {"reconnects", stats.reconnects},         {"failed_attempts", stats.failed_attempts},
          {"seconds_without_stream", stats.down_s}, {"longest_gap_s", stats.longest_down_s}};
}

}  // namespace tofnav
