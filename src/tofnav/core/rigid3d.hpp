// SPDX-License-Identifier: BSD-3-Clause
// The one rigid transform type. A variable named `b_from_a` maps points of frame a into frame b.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace tofnav {

/// Rotation plus translation [mm], column-vector convention: p_b = b_from_a * p_a.
/// The paper's T_a^b is our `b_from_a`. Compose as c_from_a = c_from_b * b_from_a.
struct Rigid3d {
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();  // unit quaternion
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();         // [mm]

  Rigid3d() = default;
  Rigid3d(const Eigen::Quaterniond& r, const Eigen::Vector3d& t)
      : rotation(r.normalized()), translation(t) {}

  static Rigid3d Identity() { return {}; }
  /// From a 3x4 or 4x4 homogeneous matrix whose rotation block is orthonormal (det +1) within
  /// `tolerance`; throws PreconditionError otherwise.
  static Rigid3d FromMatrix(const Eigen::Matrix4d& matrix, double tolerance = 1e-4);

  Eigen::Matrix4d ToMatrix() const;
  Eigen::Matrix3d RotationMatrix() const { return rotation.toRotationMatrix(); }
  Rigid3d Inverse() const;

  Eigen::Vector3d operator*(const Eigen::Vector3d& point) const {
    return rotation * point + translation;
  }
  Rigid3d operator*(const Rigid3d& other) const {
    return {rotation * other.rotation, rotation * other.translation + translation};
  }
};

/// Rotation angle between two transforms' rotations [rad] (0 .. pi).
double RotationDistanceRad(const Rigid3d& a, const Rigid3d& b);
/// Distance between two transforms' translations [mm].
double TranslationDistanceMm(const Rigid3d& a, const Rigid3d& b);

}  // namespace tofnav
