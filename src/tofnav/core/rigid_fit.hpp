// SPDX-License-Identifier: BSD-3-Clause
// Least-squares rigid fit of paired points (Kabsch / Umeyama without scale), with its FRE.
#pragma once

#include <Eigen/Core>
#include <span>
#include <vector>

#include "tofnav/core/rigid3d.hpp"

namespace tofnav {

struct RigidFitResult {
  Rigid3d target_from_source;
  double fre_rms_mm = 0.0;           // sqrt(mean |T s_i - t_i|^2)
  std::vector<double> residuals_mm;  // |T s_i - t_i| per pair
  /// Singular values of the centred cross-covariance (descending): the third near 0 means the
  /// points are (near) collinear and rotation about their line is unobservable.
  Eigen::Vector3d singular_values = Eigen::Vector3d::Zero();
};

/// Rotation and translation minimising sum |R s_i + t - t_i|^2 (Kabsch 1976, with the
/// reflection fix D = diag(1, 1, sign det(V U^T))). Throws std::invalid_argument on size
/// mismatch or fewer than 3 pairs.
RigidFitResult FitRigid(std::span<const Eigen::Vector3d> source,
                        std::span<const Eigen::Vector3d> target);

}  // namespace tofnav
