// SPDX-License-Identifier: BSD-3-Clause
// Quality of a surface registration and the decision to refuse it: RMSE, inliers, conditioning,
// target registration error predicted at the plan's targets.
#pragma once

#include <Eigen/Core>
#include <span>
#include <string>
#include <vector>

#include "tofnav/core/point_cloud.hpp"
#include "tofnav/registration/icp.hpp"
#include "tofnav/registration/pose_conditioning.hpp"

namespace tofnav {

/// Refusal thresholds: a registration failing any of them is refused, never returned as usable.
struct RegistrationThresholds {
  /// RMS point-to-plane residual of the inliers; docs/registration.md says why 0.9 mm.
  double max_rmse_mm = 0.9;
  double min_inlier_fraction = 0.5;             // of the reconstruction, within the finest ICP gate
  double min_rotation_conditioning = 0.005;     // PoseConditioning::rotation (sphere: ~0)
  double min_translation_conditioning = 0.005;  // PoseConditioning::translation (plane: ~0)
  double max_predicted_tre_mm = 1.0;            // at every given target
  /// An ICP that ran out of iterations counts as settled when its pose moved by at most this at
  /// every target over its last iterations (a tenth of the largest predicted TRE accepted): more
  /// iterations could not move the plan by anything the verdict weighs (docs/registration.md).
  double max_unsettled_mm = 0.1;
  /// Robust cost of the chosen pose over that of the best distinct alternative (0 = a clear
  /// winner, 1 = another pose fits as well): the surface is ambiguous above this ratio or, with
  /// many independent samples, above the ratio at which the alternative's excess cost is still
  /// within ambiguity_z standard errors of a mean of squares, 1 / (1 + z sqrt(2 / N_eff)),
  /// whichever is higher. docs/registration.md says why.
  double max_ambiguity = 0.7;
  double ambiguity_z = 3.0;
  /// Residual errors of a fused surface are correlated over a few millimetres (TSDF, depth
  /// bias): the TRE prediction counts one independent sample per cell of this size.
  double correlation_length_mm = 5.0;
  void Check() const;  // throws std::invalid_argument naming the field
};

enum class RegistrationStatus {
  kOk,
  kNoOverlap,          // no placement or too few correspondences: the surfaces do not overlap
  kNotConverged,       // ICP did not settle within its iterations
  kLowInlierFraction,  // too little of the reconstruction lies on the skin
  kHighRmse,
  kIllConditioned,  // the surface leaves a direction free (sphere-like vault, plane)
  kHighPredictedTre,
  kAmbiguous,  // a distinct pose fits almost as well (symmetric or featureless patch)
};

struct RegistrationQuality {
  RegistrationStatus status = RegistrationStatus::kNoOverlap;
  std::string message;  // one line with the figures; says why when refused
  double rmse_mm = 0.0;
  double inlier_fraction = 0.0;
  double residual_sigma_mm = 0.0;  // 1.4826 * MAD of the inlier residuals
  PoseConditioning conditioning;
  std::vector<double> predicted_tre_mm;  // one per target; infinity when unconstrained
  double max_predicted_tre_mm = 0.0;
  double ambiguity = 0.0;  // see RegistrationThresholds::max_ambiguity; 0 without alternatives
  /// How far the best distinct alternative pose would move the targets (the largest; without
  /// targets, the reconstruction's centroid) [mm]; 0 without alternatives.
  double ambiguity_shift_mm = 0.0;
  /// Independent samples of the fit: cells of correlation_length_mm occupied by the inliers.
  int effective_samples = 0;
  /// When the ICP ran out of iterations: how far its pose still moved at the farthest target
  /// (without targets, 100 mm from the centroid: about a head's radius) [mm]; 0 otherwise.
  double unsettled_mm = 0.0;
  bool accepted() const { return status == RegistrationStatus::kOk; }
};

/// RMS target registration error predicted at each target (ICP target frame) from the
/// Gauss-Newton covariance sigma^2 (N / N_eff) (J^T J)^-1 of the ICP solution, propagated to the
/// target's displacement omega x (q - c) + v. N_eff counts cells of `correlation_length_mm`
/// occupied by the inliers. Captures noise and sliding, not systematic bias of the surface.
/// @param source_points  the points the ICP aligned (its inlier_indices index them)
std::vector<double> PredictSurfaceTreMm(const IcpResult& icp, const Points3d& source_points,
                                        std::span<const Eigen::Vector3d> targets_in_target,
                                        double correlation_length_mm);

/// The quality figures of an ICP solution and the refusal decision.
/// @param ambiguity  cost ratio to the best distinct alternative pose (0 when there is none)
/// @param ambiguity_shift_mm  how far that alternative moves the targets
RegistrationQuality AssessRegistration(const IcpResult& icp, const Points3d& source_points,
                                       std::span<const Eigen::Vector3d> targets_in_target,
                                       const RegistrationThresholds& thresholds = {},
                                       double ambiguity = 0.0, double ambiguity_shift_mm = 0.0);

/// The ambiguity ratio above which a fit of `effective_samples` independent samples is refused
/// (RegistrationThresholds::max_ambiguity, ambiguity_z).
double AmbiguityLimit(int effective_samples, const RegistrationThresholds& thresholds);

/// "ok", "no-overlap", ... for reports.
const char* ToString(RegistrationStatus status);

}  // namespace tofnav
