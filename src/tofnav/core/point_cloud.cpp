// SPDX-License-Identifier: BSD-3-Clause
// Point clouds.
#include "tofnav/core/point_cloud.hpp"

#include "tofnav/core/require.hpp"

namespace tofnav {

void PointCloud::CheckConsistent() const {
  const std::size_t n = points.size();
  Require(normals.empty() || normals.size() == n, "point cloud: normals count != point count");
  Require(colors.empty() || colors.size() == n, "point cloud: colors count != point count");
  Require(scalars.empty() || scalars.size() == n, "point cloud: scalars count != point count");
}

Points3d Transform(const Rigid3d& b_from_a, const Points3d& points_in_a) {
  Points3d out;
  out.reserve(points_in_a.size());
  for (const Eigen::Vector3d& p : points_in_a) out.push_back(b_from_a * p);
  return out;
}

PointCloud Transform(const Rigid3d& b_from_a, const PointCloud& cloud_in_a) {
  cloud_in_a.CheckConsistent();
  PointCloud out = cloud_in_a;
  out.points = Transform(b_from_a, cloud_in_a.points);
  for (Eigen::Vector3d& n : out.normals) n = b_from_a.rotation * n;
  return out;
}

}  // namespace tofnav
