// SPDX-License-Identifier: BSD-3-Clause
// When a filtered orientation is still SETTLING: its expected RMS error above a limit
// (TrackedTool::filtered_rotation_sd_rad; docs/tracking.md 1, "A pose that is still settling").
#pragma once

#include <optional>

#include "tofnav/core/units.hpp"

namespace tofnav {

/// The default limit: 0.35 deg, the orientation the suite holds a reference plate to
/// (docs/navigation.md 1.2).
inline constexpr double kSettledRotationSdRad = 0.35 * kDegToRad;

/// SETTLING: an expected RMS error reported and above `limit_rad`. None reported: no claim.
inline bool IsSettling(const std::optional<double>& rotation_sd_rad, double limit_rad) {
  return rotation_sd_rad && *rotation_sd_rad > limit_rad;
}

}  // namespace tofnav
