// SPDX-License-Identifier: BSD-3-Clause
// The per-frame navigation CSV of `tofnav navigate --out` (docs/navigation.md): write and read.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "tofnav/core/rigid3d.hpp"
#include "tofnav/imaging/trajectory.hpp"
#include "tofnav/pipeline/navigator.hpp"

namespace tofnav {

/// The header line (with its newline).
std::string NavigationCsvHeader();
/// One frame's row (with its newline): status, world_from_image, the active trajectory placed,
/// instrument and guidance; empty cells for what the frame lacks.
std::string NavigationCsvRow(const NavigationState& state, const std::vector<Trajectory>& plan);

/// One row that placed the plan: its time and world_from_image.
struct PlacedFrame {
  double timestamp_s = 0.0;
  Rigid3d world_from_image;
};

/// The rows of a navigation CSV with a world_from_image. Throws std::runtime_error on a file that
/// cannot be opened, lacks the columns, or holds a row whose time or pose is not numbers.
std::vector<PlacedFrame> ReadNavigationCsv(const std::filesystem::path& path);

}  // namespace tofnav
