// SPDX-License-Identifier: BSD-3-Clause
// Rotation vectors (axis times angle): the tangent space in which filters and fits treat
// small rotations.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace tofnav {

/// The rotation vector (axis times angle, angle in 0 .. pi) [rad] of a unit quaternion.
Eigen::Vector3d RotationVector(const Eigen::Quaterniond& q);
/// The unit quaternion of a rotation vector [rad] (exact for every non-zero angle).
Eigen::Quaterniond FromRotationVector(const Eigen::Vector3d& rotation_vector_rad);

}  // namespace tofnav
