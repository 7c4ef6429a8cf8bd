// SPDX-License-Identifier: BSD-3-Clause
// Eigen-analysis of the pose information matrix (Gelfand et al. 2003, "geometrically stable
// sampling": the same 6x6 covariance and its eigenvectors name the sliding directions).
#include "tofnav/registration/pose_conditioning.hpp"

#include <algorithm>

#include "tofnav/core/dense_solvers.hpp"
#include "tofnav/core/require.hpp"

namespace tofnav {
namespace {

/// Pseudo-inverse of a symmetric positive semi-definite 3x3 block.
Eigen::Matrix3d PseudoInverse(const Eigen::Matrix3d& block) {
  const auto solver = DecomposeSymmetric(block);
  const double largest = std::max(solver.values.cwiseAbs().maxCoeff(), 1e-300);
  Eigen::Vector3d inverse = Eigen::Vector3d::Zero();
  for (int i = 0; i < 3; ++i) {
    if (solver.values(i) > 1e-12 * largest) inverse(i) = 1.0 / solver.values(i);
  }
  return solver.vectors * inverse.asDiagonal() * solver.vectors.transpose();
}

double SmallestEigenvalue(const Eigen::Matrix3d& block) {
  return std::max(DecomposeSymmetric(block).values(0), 0.0);
}

}  // namespace

PoseConditioning ComputeConditioning(const Matrix6d& information, int count, double radius_mm) {
  Require(radius_mm > 0.0, "ComputeConditioning: radius_mm must be > 0");
  PoseConditioning result;
  if (count <= 0) return result;
  Vector6d scale;
  scale << Eigen::Vector3d::Constant(1.0 / radius_mm), Eigen::Vector3d::Ones();
  const Matrix6d scaled = scale.asDiagonal() * information * scale.asDiagonal() / count;
  const auto solver = DecomposeSymmetric(scaled);
  result.eigenvalues = solver.values.cwiseMax(0.0);
  result.weakest_direction = solver.vectors.col(0);
  const double largest = result.eigenvalues(5);
  if (!(largest > 0.0)) return result;
  result.overall = result.eigenvalues(0) / largest;
  const Eigen::Matrix3d rr = scaled.topLeftCorner<3, 3>();
  const Eigen::Matrix3d rt = scaled.topRightCorner<3, 3>();
  const Eigen::Matrix3d tt = scaled.bottomRightCorner<3, 3>();
  result.rotation = SmallestEigenvalue(rr - rt * PseudoInverse(tt) * rt.transpose()) / largest;
  result.translation = SmallestEigenvalue(tt - rt.transpose() * PseudoInverse(rr) * rt) / largest;
  return result;
}

}  // namespace tofnav
