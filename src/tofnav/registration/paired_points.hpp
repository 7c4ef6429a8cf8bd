// SPDX-License-Identifier: BSD-3-Clause
// Paired-point (fiducial) registration with FRE and the Fitzpatrick TRE prediction.
#pragma once

#include <Eigen/Core>
#include <span>
#include <vector>

#include "tofnav/core/rigid3d.hpp"

namespace tofnav {

struct PairedPointResult {
  Rigid3d target_from_source;
  double fre_rms_mm = 0.0;           // RMS fiducial registration error
  std::vector<double> residuals_mm;  // |target_from_source * source_i - target_i|
};

/// Least-squares rigid transform between paired points (Horn 1987 / Umeyama 1991: SVD of the
/// cross-covariance, reflection excluded). Throws PreconditionError for fewer than 3 pairs,
/// different counts or (near-)collinear points.
PairedPointResult RegisterPairedPoints(std::span<const Eigen::Vector3d> source,
                                       std::span<const Eigen::Vector3d> target);

/// Expected RMS target registration error at `target` (fiducial frame) for fiducials localised
/// with RMS error `fle_rms_mm` (3-D, isotropic, independent), Fitzpatrick, West & Maurer 1998:
///   TRE^2 = FLE^2 / N * (1 + 1/3 * sum_k d_k^2 / f_k^2),
/// d_k the target's distance from principal axis k of the fiducials, f_k their RMS distance.
double PredictFiducialTreMm(std::span<const Eigen::Vector3d> fiducials, double fle_rms_mm,
                            const Eigen::Vector3d& target);

/// FLE estimated from a measured FRE: E[FRE^2] = (1 - 2 / N) FLE^2 (Fitzpatrick et al. 1998).
double EstimateFleFromFreMm(double fre_rms_mm, std::size_t fiducial_count);

}  // namespace tofnav
