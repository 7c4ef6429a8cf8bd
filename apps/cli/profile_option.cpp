// SPDX-License-Identifier: BSD-3-Clause
#include "profile_option.hpp"

#include "tofnav/recording/hl2ss_recording.hpp"

namespace tofnav {

void AddProfileOptions(CLI::App& app, std::string& profile,
                       std::optional<std::uint32_t>& bitrate_bps) {
  app.add_option("--profile", profile,
                 "hl2ss stream profile: " + Hl2ssStreamProfileChoices() +
                     " (raw = same+raw; h264 = H.264 Main)")
      ->check([](const std::string& text) {
        return ParseHl2ssStreamProfile(text) ? std::string()
                                             : "not an hl2ss profile: " + text + " (one of " +
                                                   Hl2ssStreamProfileChoices() + ")";
      })
      ->capture_default_str();
  app.add_option("--bitrate-bps", bitrate_bps,
                 "H.264/H.265 bitrate [bit/s] (unset: the hl2ss client's default for the profile)")
      ->check(CLI::Range(10000u, 1000000000u));
}

}  // namespace tofnav
