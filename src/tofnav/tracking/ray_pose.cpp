// SPDX-License-Identifier: BSD-3-Clause
// PnP on unit rays: Gauss-Newton on the object-space collinearity error.
#include "tofnav/tracking/ray_pose.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <vector>

#include "tofnav/core/require.hpp"

namespace tofnav {

void RayPoseOptions::Check() const {
  Require(max_iterations >= 1, "RayPoseOptions::max_iterations must be >= 1");
  Require(tolerance_mm > 0.0, "RayPoseOptions::tolerance_mm must be > 0");
}

RayPoseResult EstimatePoseFromRays(std::span<const Eigen::Vector3d> markers_in_tool,
                                   std::span<const Eigen::Vector3d> rays_in_ahat,
                                   const Rigid3d& initial_ahat_from_tool,
                                   const RayPoseOptions& options) {
  options.Check();
  const std::size_t n = markers_in_tool.size();
  Require(n >= 3 && rays_in_ahat.size() == n, "EstimatePoseFromRays: needs >= 3 marker-ray pairs");
  std::vector<Eigen::Matrix3d> off_ray(n);  // I - r r^T: the part of a point off its ray
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d r = rays_in_ahat[i].normalized();
    off_ray[i] = Eigen::Matrix3d::Identity() - r * r.transpose();
  }
  RayPoseResult result;
  Eigen::Matrix3d rotation = initial_ahat_from_tool.RotationMatrix();
  Eigen::Vector3d translation = initial_ahat_from_tool.translation;
  // Gauss-Newton on e_i = (I - r_i r_i^T)(R m_i + t), R <- Exp(w) R: de/dw = -(I - r r^T)[R m]x.
  for (result.iterations = 1; result.iterations <= options.max_iterations; ++result.iterations) {
    Eigen::Matrix<double, 6, 6> h = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::Vector3d rm = rotation * markers_in_tool[i];
      Eigen::Matrix<double, 3, 6> j;
      Eigen::Matrix3d skew;
      skew << 0, -rm.z(), rm.y(), rm.z(), 0, -rm.x(), -rm.y(), rm.x(), 0;
      j.leftCols<3>() = -off_ray[i] * skew;
      j.rightCols<3>() = off_ray[i];
      const Eigen::Vector3d e = off_ray[i] * (rm + translation);
      h += j.transpose() * j;
      g += j.transpose() * e;
    }
    const Eigen::Matrix<double, 6, 1> step = -h.ldlt().solve(g);
    if (!step.allFinite()) break;
    const Eigen::Vector3d w = step.head<3>();
    if (w.norm() > 0.0)
      rotation = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix() * rotation;
    translation += step.tail<3>();
    double moved = step.tail<3>().norm();
    for (std::size_t i = 0; i < n; ++i)
      moved = std::max(moved, step.tail<3>().norm() + w.norm() * markers_in_tool[i].norm());
    if (moved < options.tolerance_mm) {
      result.converged = true;
      break;
    }
  }
  result.ahat_from_tool = Rigid3d(Eigen::Quaterniond(rotation), translation);
  double sum2 = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    sum2 += (off_ray[i] * (rotation * markers_in_tool[i] + translation)).squaredNorm();
  }
  result.rms_ray_distance_mm = std::sqrt(sum2 / static_cast<double>(n));
  return result;
}

}  // namespace tofnav
