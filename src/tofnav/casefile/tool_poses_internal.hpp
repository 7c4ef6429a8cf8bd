// SPDX-License-Identifier: BSD-3-Clause
// Shared by the tool poses CSV and JSON codecs (tool_poses_io.cpp, tool_poses_json.cpp) only.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string_view>
#include <vector>

#include "tofnav/casefile/tool_poses_io.hpp"

namespace tofnav::internal {

/// A pose from (w, x, y, z, tx, ty, tz); IoError unless finite with a unit quaternion.
std::optional<Rigid3d> PoseFromValues(const std::array<double, 7>& values,
                                      const std::filesystem::path& path,
                                      std::optional<std::uint64_t> offset);
/// ParseToolStatus or IoError.
ToolStatus StatusFromName(std::string_view name, const std::filesystem::path& path,
                          std::optional<std::uint64_t> offset);
std::vector<ToolPoseRecord> DecodeToolPosesJson(std::string_view text,
                                                const std::filesystem::path& path);

}  // namespace tofnav::internal
