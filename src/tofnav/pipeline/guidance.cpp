// SPDX-License-Identifier: BSD-3-Clause
// Guidance quantities: distance to the entry, angle to the planned axis, remaining depth.
#include "tofnav/pipeline/guidance.hpp"

#include <cmath>

#include "tofnav/core/require.hpp"

namespace tofnav {

double AngleBetweenRad(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  // atan2(|a x b|, a . b) keeps full precision near 0 and pi, unlike acos.
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

Guidance ComputeGuidance(const Eigen::Vector3d& tip, const Eigen::Vector3d& axis,
                         const Eigen::Vector3d& entry, const Eigen::Vector3d& target) {
  const Eigen::Vector3d planned = target - entry;
  Require(planned.norm() > 0.0, "ComputeGuidance: entry and target coincide");
  Require(axis.norm() > 0.0, "ComputeGuidance: zero instrument axis");
  const Eigen::Vector3d direction = planned.normalized();
  const Eigen::Vector3d from_entry = tip - entry;
  Guidance g;
  g.tip_to_entry_mm = from_entry.norm();
  g.angle_to_axis_rad = AngleBetweenRad(axis, direction);
  g.remaining_depth_mm = (target - tip).dot(direction);
  g.lateral_offset_mm = (from_entry - from_entry.dot(direction) * direction).norm();
  return g;
}

}  // namespace tofnav
