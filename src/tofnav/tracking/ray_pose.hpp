// SPDX-License-Identifier: BSD-3-Clause
// Marker-structure poses on rays: rays alone (PnP), or rays plus ranges weighted anisotropically.
#pragma once

#include <Eigen/Core>
#include <span>

#include "tofnav/core/rigid3d.hpp"

namespace tofnav {

struct RayPoseOptions {
  int max_iterations = 50;
  double tolerance_mm = 1e-4;  // stop when a step moves every marker less than this
  void Check() const;
};

struct RayPoseResult {
  Rigid3d ahat_from_tool;
  double rms_ray_distance_mm = 0.0;  // RMS distance of the posed markers from their rays
  int iterations = 0;
  bool converged = false;
};

/// d(R m + t) / d(w, t) for the update R <- Exp(w) R, t <- t + dt: [-[R m]x | I] (3 x 6), from
/// the rotated point R m.
Eigen::Matrix<double, 3, 6> PoseJacobian(const Eigen::Vector3d& rotated_point);

/// Minimises sum |(I - r_i r_i^T)(R m_i + t)|^2, the object-space collinearity error of Lu,
/// Hager & Mjolsness (2000), by Gauss-Newton from `initial_ahat_from_tool` (e.g. a Kabsch fit to
/// range-based centres, which also picks the right branch of a planar structure's two poses). Uses
/// only the rays, so the result is independent of the ToF range error: the reference of the f_rf
/// experiment (Sec. III-A.1). Throws std::invalid_argument on fewer than 3 pairs or a size
/// mismatch.
/// @param rays_in_ahat  unit rays through the marker centres, one per marker
RayPoseResult EstimatePoseFromRays(std::span<const Eigen::Vector3d> markers_in_tool,
                                   std::span<const Eigen::Vector3d> rays_in_ahat,
                                   const Rigid3d& initial_ahat_from_tool,
                                   const RayPoseOptions& options = {});

/// One marker seen along a ray at a range, with its lateral and along-ray standard deviations.
struct RayRangeObservation {
  Eigen::Vector3d ray_in_ahat = Eigen::Vector3d::UnitZ();  // unit ray through the centre
  double range_mm = 0.0;                                   // centre range along the ray
  double lateral_sigma_mm = 1.0;                           // > 0, per axis across the ray
  double range_sigma_mm = 1.0;                             // > 0, along the ray
};

/// Maximum-likelihood pose under anisotropic Gaussian marker errors: minimises
/// sum |(I - r r^T)(R m + t)|^2 / s_lat^2 + (r . (R m + t) - d)^2 / s_range^2 by Gauss-Newton
/// from `initial_ahat_from_tool`. A ToF marker's range is far noisier than its sub-pixel ray, and
/// an isotropic (Kabsch) fit turns that range noise into tilt. rms_ray_distance_mm is the RMS
/// lateral residual. Throws std::invalid_argument on fewer than 3 pairs, a size mismatch or a
/// sigma <= 0.
RayPoseResult EstimatePoseFromRaysAndRanges(std::span<const Eigen::Vector3d> markers_in_tool,
                                            std::span<const RayRangeObservation> observations,
                                            const Rigid3d& initial_ahat_from_tool,
                                            const RayPoseOptions& options = {});

/// Covariance of a pose fitted to `observations` under their sigmas: (J^T W J)^-1 at
/// `ahat_from_tool`, the first three coordinates a small rotation vector w in `ahat`
/// (R <- Exp(w) R) [rad], the last three the translation [mm] (docs/tracking.md 9.5).
/// Non-finite where the markers do not fix the pose. Throws as EstimatePoseFromRaysAndRanges.
Eigen::Matrix<double, 6, 6> RayRangePoseCovariance(
    std::span<const Eigen::Vector3d> markers_in_tool,
    std::span<const RayRangeObservation> observations, const Rigid3d& ahat_from_tool);

}  // namespace tofnav
