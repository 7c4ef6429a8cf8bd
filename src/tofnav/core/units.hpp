// SPDX-License-Identifier: BSD-3-Clause
// The unit conversions used across tofnav (mm, seconds and radians inside; metres and degrees
// only at the formats and reports that use them).
#pragma once

#include <numbers>

namespace tofnav {

inline constexpr double kMmPerMetre = 1000.0;
inline constexpr double kRadToDeg = 180.0 / std::numbers::pi;
inline constexpr double kDegToRad = std::numbers::pi / 180.0;
inline constexpr double kTwoPi = 2.0 * std::numbers::pi;

}  // namespace tofnav
