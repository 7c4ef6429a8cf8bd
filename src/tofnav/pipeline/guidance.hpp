// SPDX-License-Identifier: BSD-3-Clause
// Guidance quantities of a tracked instrument against a planned trajectory.
#pragma once

#include <Eigen/Core>

#include "tofnav/core/rigid3d.hpp"

namespace tofnav {

/// The instrument against a planned trajectory, all in one frame [mm, rad].
struct Guidance {
  double tip_to_entry_mm = 0.0;     // |tip - entry|
  double angle_to_axis_rad = 0.0;   // instrument axis vs entry -> target direction (0 .. pi)
  double remaining_depth_mm = 0.0;  // (target - tip) along the planned direction (< 0: past it)
  double lateral_offset_mm = 0.0;   // distance of the tip from the planned line
};

/// Guidance of an instrument whose tip is at `tip` and whose axis points along `axis` (towards
/// the tip, any length > 0), against the line `entry` -> `target`; every point in one frame.
/// Throws PreconditionError when entry == target or the axis is zero.
Guidance ComputeGuidance(const Eigen::Vector3d& tip, const Eigen::Vector3d& axis,
                         const Eigen::Vector3d& entry, const Eigen::Vector3d& target);

/// Angle between two directions [rad] (0 .. pi), robust near 0 and pi.
double AngleBetweenRad(const Eigen::Vector3d& a, const Eigen::Vector3d& b);

}  // namespace tofnav
