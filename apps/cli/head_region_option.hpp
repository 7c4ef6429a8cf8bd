// SPDX-License-Identifier: BSD-3-Clause
// The --head-region auto|off option shared by identify, correct and reconstruct.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "tofnav/correction/head_region.hpp"

namespace tofnav {

/// auto (default): the automatic head region (docs/correction.md section 1); off: every valid
/// pixel in range (the ROI radius or box still applies).
inline CLI::Option* AddHeadRegionOption(CLI::App& app, HeadRegionOptions& options) {
  return app
      .add_option_function<std::string>(
          "--head-region", [&options](const std::string& v) { options.enabled = v == "auto"; },
          "auto: only the automatic head region (drops the headframe board, tool plates and "
          "fragments); off: every valid pixel")
      ->check(CLI::IsMember({"auto", "off"}))
      ->default_str(options.enabled ? "auto" : "off");
}

}  // namespace tofnav
