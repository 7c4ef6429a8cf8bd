// SPDX-License-Identifier: BSD-3-Clause
// `tofnav navigate hl2ss://...`: configuration, link messages and counts (docs/navigation.md).
#include "navigate_live.hpp"

#include <cstdio>
#include <utility>

namespace tofnav {

std::unique_ptr<LiveHl2ssSource> MakeLiveSource(
    const Hl2ssEndpoint& endpoint, const Hl2ssStreamProfile& profile,
    std::optional<std::uint32_t> bitrate_bps, const LiveLinkOptions& options,
    std::optional<std::vector<std::uint8_t>> device_calibration, const std::atomic<bool>* stop,
    LiveHl2ssSource::OnReport on_report) {
  Hl2ssAhatConfig config;
  config.profile_z = profile.profile_z;
  config.profile_ab = profile.profile_ab;
  config.bitrate_bps =
      bitrate_bps.value_or(Hl2ssDefaultAhatBitrate(config.profile_z, config.profile_ab));
  config.encoder_options = Hl2ssDefaultEncoderOptions(config.profile_ab);
  return std::make_unique<LiveHl2ssSource>(endpoint, config, options, std::move(device_calibration),
                                           std::move(on_report), stop);
}

std::string LossyDepthWarning(const Hl2ssStreamProfile& profile) {
  return Hl2ssStreamProfileName(profile) +
         " sends depth in 4 mm steps with codec noise (wrapping above 1023 mm) and AB at half "
         "resolution: in simulation the reference tools track at 1.3-1.8 mm RMS on it against "
         "0.16-0.21 mm on zdepth+h265, which costs less Wi-Fi (docs/suite.md, \"Stream "
         "profiles\")" +
         std::string(profile.profile_ab == Hl2ssVideoProfile::kH265Main
                         ? "; decoding its 15 Mbit/s adds about 4 ms to every frame's latency "
                           "against 0.9 ms for zdepth+h265 (docs/benchmarks.md)"
                         : "");
}

void ReportLink(const LinkReport& report, bool status_line) {
  if (report.message.empty()) return;
  std::fprintf(stderr, "%stofnav navigate: %s\n", status_line ? "\r\033[K" : "",
               report.message.c_str());
}

nlohmann::ordered_json LinkSummary(const LiveLinkStats& stats) {
  return {{"disconnects", stats.disconnects},       {"stalls", stats.stalls},
          {"reconnects", stats.reconnects},         {"failed_attempts", stats.failed_attempts},
          {"seconds_without_stream", stats.down_s}, {"longest_gap_s", stats.longest_down_s},
          {"dropped_frames", stats.dropped_frames}};
}

}  // namespace tofnav
