// SPDX-License-Identifier: BSD-3-Clause
// Point clouds: positions [mm] with optional normals, colours and one scalar per point.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "tofnav/core/rigid3d.hpp"

namespace tofnav {

using Points3d = std::vector<Eigen::Vector3d>;
using Rgb8 = Eigen::Matrix<std::uint8_t, 3, 1>;

/// Points in one named frame (the variable name says which: `head_in_tool`).
/// Optional attributes are either empty or have one entry per point.
struct PointCloud {
  Points3d points;   // [mm]
  Points3d normals;  // unit vectors, or empty
  std::vector<Rgb8> colors;
  std::vector<float> scalars;  // e.g. error [mm]; empty when absent

  std::size_t size() const { return points.size(); }
  /// Throws PreconditionError when an attribute's size differs from the point count.
  void CheckConsistent() const;
};

/// b_from_a applied to every point (and rotation to every normal).
PointCloud Transform(const Rigid3d& b_from_a, const PointCloud& cloud_in_a);
Points3d Transform(const Rigid3d& b_from_a, const Points3d& points_in_a);

}  // namespace tofnav
