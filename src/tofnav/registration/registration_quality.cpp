// SPDX-License-Identifier: BSD-3-Clause
// Registration quality: covariance-based TRE prediction and the refusal rules.
#include "tofnav/registration/registration_quality.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <tuple>

#include "tofnav/core/dense_solvers.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/registration/sampling.hpp"

namespace tofnav {
namespace {

constexpr double kSingular = 1e-12;          // relative eigenvalue below which J^T J is singular
constexpr double kUnsettledLeverMm = 100.0;  // without targets: about a head's radius

std::string Format(const char* format, double a, double b, double c = 0.0) {
  char text[256];
  std::snprintf(text, sizeof(text), format, a, b, c);
  return text;
}

/// The first failed rule, or kOk; with its message.
std::pair<RegistrationStatus, std::string> Decide(const IcpResult& icp,
                                                  const RegistrationQuality& q,
                                                  const RegistrationThresholds& t) {
  using S = RegistrationStatus;
  if (icp.correspondences < 6) {
    return {S::kNoOverlap, Format("the reconstruction does not overlap the skin (%.0f matched "
                                  "points, inlier fraction %.3f)",
                                  icp.correspondences, q.inlier_fraction)};
  }
  if (q.inlier_fraction < t.min_inlier_fraction) {
    return {S::kLowInlierFraction,
            Format("inlier fraction %.3f is below %.3f: too little of the reconstruction lies on "
                   "the skin",
                   q.inlier_fraction, t.min_inlier_fraction)};
  }
  if (q.rmse_mm > t.max_rmse_mm) {
    return {S::kHighRmse, Format("RMSE %.3f mm is above %.3f mm", q.rmse_mm, t.max_rmse_mm)};
  }
  if (q.conditioning.rotation < t.min_rotation_conditioning) {
    return {S::kIllConditioned,
            Format("the surface leaves the rotation free (conditioning %.2g < %.2g): a "
                   "sphere-like surface can slide; include face features",
                   q.conditioning.rotation, t.min_rotation_conditioning)};
  }
  if (q.conditioning.translation < t.min_translation_conditioning) {
    return {S::kIllConditioned,
            Format("the surface leaves the translation free (conditioning %.2g < %.2g)",
                   q.conditioning.translation, t.min_translation_conditioning)};
  }
  if (const double limit = AmbiguityLimit(q.effective_samples, t); q.ambiguity > limit) {
    return {S::kAmbiguous,
            Format("another pose fits almost as well (cost ratio %.2f > %.2f, %.0f mm away at a "
                   "target): the surface is too symmetric or featureless to register",
                   q.ambiguity, limit, q.ambiguity_shift_mm)};
  }
  // Out of iterations but still by less than a tenth of the accepted TRE: settled for the plan.
  // (Too few correspondences were refused above.)
  const bool settled = icp.out_of_iterations && q.unsettled_mm <= t.max_unsettled_mm;
  if (!icp.converged && !settled) {
    return {S::kNotConverged, Format("ICP did not converge in %.0f iterations (inlier fraction "
                                     "%.3f; the pose still moved %.3f mm at a target)",
                                     icp.iterations, q.inlier_fraction, q.unsettled_mm)};
  }
  if (q.max_predicted_tre_mm > t.max_predicted_tre_mm) {
    return {S::kHighPredictedTre, Format("predicted TRE %.3f mm at a target is above %.3f mm",
                                         q.max_predicted_tre_mm, t.max_predicted_tre_mm)};
  }
  return {S::kOk, Format("RMSE %.3f mm, inlier fraction %.3f", q.rmse_mm, q.inlier_fraction)};
}

}  // namespace

double AmbiguityLimit(int effective_samples, const RegistrationThresholds& t) {
  if (effective_samples < 1) return t.max_ambiguity;
  const double noise = t.ambiguity_z * std::sqrt(2.0 / effective_samples);
  return std::max(t.max_ambiguity, 1.0 / (1.0 + noise));
}

void RegistrationThresholds::Check() const {
  Require(max_rmse_mm > 0.0, "RegistrationThresholds.max_rmse_mm must be > 0");
  Require(min_inlier_fraction >= 0.0 && min_inlier_fraction <= 1.0,
          "RegistrationThresholds.min_inlier_fraction must lie in [0, 1]");
  Require(min_rotation_conditioning >= 0.0 && min_translation_conditioning >= 0.0,
          "RegistrationThresholds.min_*_conditioning must be >= 0");
  Require(max_predicted_tre_mm > 0.0, "RegistrationThresholds.max_predicted_tre_mm must be > 0");
  Require(max_unsettled_mm >= 0.0, "RegistrationThresholds.max_unsettled_mm must be >= 0");
  Require(correlation_length_mm > 0.0, "RegistrationThresholds.correlation_length_mm must be > 0");
  Require(max_ambiguity > 0.0, "RegistrationThresholds.max_ambiguity must be > 0");
  Require(ambiguity_z >= 0.0, "RegistrationThresholds.ambiguity_z must be >= 0");
}

namespace {

// Cells of correlation_length_mm occupied by the ICP's inliers: its independent samples.
std::size_t EffectiveSamples(const IcpResult& icp, const Points3d& source_points,
                             double correlation_length_mm) {
  return VoxelSubsample(Gather(source_points, icp.inlier_indices), correlation_length_mm).size();
}

// PredictSurfaceTreMm with the effective sample count already known.
std::vector<double> PredictTre(const IcpResult& icp, std::size_t effective_samples,
                               std::span<const Eigen::Vector3d> targets_in_target) {
  std::vector<double> tre(targets_in_target.size(), std::numeric_limits<double>::infinity());
  const std::size_t inliers = icp.inlier_indices.size();
  if (inliers < 6) return tre;
  const double inflation =  // N / N_eff >= 1
      static_cast<double>(inliers) / static_cast<double>(effective_samples);
  const auto solver = DecomposeSymmetric(icp.information);
  const Vector6d& values = solver.values;
  if (!(values(0) > kSingular * values(5))) return tre;
  const Matrix6d covariance = icp.residual_sigma_mm * icp.residual_sigma_mm * inflation *
                              solver.vectors * values.cwiseInverse().asDiagonal() *
                              solver.vectors.transpose();
  for (std::size_t i = 0; i < targets_in_target.size(); ++i) {
    const Eigen::Vector3d lever = targets_in_target[i] - icp.centre_in_target;
    Eigen::Matrix<double, 3, 6> jacobian;  // displacement omega x lever + v
    jacobian << -(Eigen::Matrix3d() << 0, -lever.z(), lever.y(), lever.z(), 0, -lever.x(),
                  -lever.y(), lever.x(), 0)
                     .finished(),
        Eigen::Matrix3d::Identity();
    tre[i] = std::sqrt((jacobian * covariance * jacobian.transpose()).trace());
  }
  return tre;
}

}  // namespace

std::vector<double> PredictSurfaceTreMm(const IcpResult& icp, const Points3d& source_points,
                                        std::span<const Eigen::Vector3d> targets_in_target,
                                        double correlation_length_mm) {
  return PredictTre(icp, EffectiveSamples(icp, source_points, correlation_length_mm),
                    targets_in_target);
}

RegistrationQuality AssessRegistration(const IcpResult& icp, const Points3d& source_points,
                                       std::span<const Eigen::Vector3d> targets_in_target,
                                       const RegistrationThresholds& thresholds, double ambiguity,
                                       double ambiguity_shift_mm) {
  thresholds.Check();
  RegistrationQuality q;
  q.rmse_mm = icp.rmse_mm;
  q.inlier_fraction = icp.inlier_fraction;
  q.residual_sigma_mm = icp.residual_sigma_mm;
  q.conditioning = icp.conditioning;
  q.ambiguity = ambiguity;
  q.ambiguity_shift_mm = ambiguity_shift_mm;
  const std::size_t samples =
      EffectiveSamples(icp, source_points, thresholds.correlation_length_mm);
  q.effective_samples = static_cast<int>(samples);
  q.predicted_tre_mm = PredictTre(icp, samples, targets_in_target);
  for (const double tre : q.predicted_tre_mm)
    q.max_predicted_tre_mm = std::max(q.max_predicted_tre_mm, tre);
  if (icp.out_of_iterations) {  // rotation moves a target by its lever from the centroid
    double lever_mm = targets_in_target.empty() ? kUnsettledLeverMm : 0.0;
    for (const Eigen::Vector3d& p : targets_in_target)
      lever_mm = std::max(lever_mm, (p - icp.centre_in_target).norm());
    q.unsettled_mm = icp.unsettled_translation_mm + icp.unsettled_rotation_rad * lever_mm;
  }
  std::tie(q.status, q.message) = Decide(icp, q, thresholds);
  return q;
}

const char* ToString(RegistrationStatus status) {
  switch (status) {
    case RegistrationStatus::kOk:
      return "ok";
    case RegistrationStatus::kNoOverlap:
      return "no-overlap";
    case RegistrationStatus::kNotConverged:
      return "not-converged";
    case RegistrationStatus::kLowInlierFraction:
      return "low-inlier-fraction";
    case RegistrationStatus::kHighRmse:
      return "high-rmse";
    case RegistrationStatus::kIllConditioned:
      return "ill-conditioned";
    case RegistrationStatus::kHighPredictedTre:
      return "high-predicted-tre";
    case RegistrationStatus::kAmbiguous:
      return "ambiguous";
  }
  return "unknown";
}

}  // namespace tofnav
