// SPDX-License-Identifier: BSD-3-Clause
// --profile and --bitrate-bps: the hl2ss stream profile of the commands that write, serve, read
// live or evaluate AHAT streams (docs/ahat.md 3.6).
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <optional>
#include <string>

namespace tofnav {

/// Adds --profile (checked with ParseHl2ssStreamProfile; `profile` holds the default) and
/// --bitrate-bps (H.264/H.265 only; unset: the hl2ss client's default for the profile).
void AddProfileOptions(CLI::App& app, std::string& profile,
                       std::optional<std::uint32_t>& bitrate_bps);

}  // namespace tofnav
