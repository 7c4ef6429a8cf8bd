// SPDX-License-Identifier: BSD-3-Clause
// CalibratePivot: normal equations of the stacked pivot constraints (docs/tracking.md, "Pivot
// calibration").
#include "tofnav/tracking/pivot_calibration.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "tofnav/core/dense_solvers.hpp"
#include "tofnav/core/require.hpp"

namespace tofnav {
namespace {

// Largest angle between two of the directions (at most ~1000 of them, evenly picked).
double LargestAngleRad(const std::vector<Eigen::Vector3d>& directions) {
  const std::size_t stride = std::max<std::size_t>(1, directions.size() / 1000);
  double best_cos = 1.0;
  for (std::size_t i = 0; i < directions.size(); i += stride) {
    for (std::size_t j = i + stride; j < directions.size(); j += stride) {
      best_cos = std::min(best_cos, directions[i].dot(directions[j]));
    }
  }
  return std::acos(std::clamp(best_cos, -1.0, 1.0));
}

// Tip, pivot and RMS from the normal equations of all `poses`.
void FitPivot(std::span<const Rigid3d> poses, PivotCalibrationResult& result) {
  // Each pose: [R_i  -I] [tip; pivot] = -t_i. Normal equations A^T A x = A^T b, with
  // R_i^T R_i = I, so A^T A = sum [[I, -R_i^T], [-R_i, I]].
  Eigen::Matrix<double, 6, 6> normal = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> rhs = Eigen::Matrix<double, 6, 1>::Zero();
  for (const Rigid3d& pose : poses) {
    const Eigen::Matrix3d r = pose.RotationMatrix();
    normal.topLeftCorner<3, 3>() += Eigen::Matrix3d::Identity();
    normal.topRightCorner<3, 3>() -= r.transpose();
    normal.bottomLeftCorner<3, 3>() -= r;
    normal.bottomRightCorner<3, 3>() += Eigen::Matrix3d::Identity();
    rhs.head<3>() -= r.transpose() * pose.translation;
    rhs.tail<3>() += pose.translation;
  }
  const Eigen::Matrix<double, 6, 1> x = SolveSymmetric(normal, rhs);
  result.tip_in_instrument = x.head<3>();
  result.pivot_in_reference = x.tail<3>();
  double sum_sq = 0.0;
  for (const Rigid3d& pose : poses) {
    sum_sq += (pose * result.tip_in_instrument - result.pivot_in_reference).squaredNorm();
  }
  result.rms_mm = std::sqrt(sum_sq / static_cast<double>(poses.size()));
}

}  // namespace

void PivotCalibrationOptions::Check() const {
  Require(min_poses >= 3, "PivotCalibrationOptions.min_poses must be >= 3");
  Require(std::isfinite(min_angular_range_rad) && min_angular_range_rad >= 0.0,
          "PivotCalibrationOptions.min_angular_range_rad must be >= 0");
  Require(std::isfinite(outlier_factor) && outlier_factor >= 0.0 && max_refits >= 0,
          "PivotCalibrationOptions: outlier_factor and max_refits must be >= 0");
}

const char* ToString(PivotStatus status) {
  switch (status) {
    case PivotStatus::kOk:
      return "OK";
    case PivotStatus::kTooFewPoses:
      return "TOO_FEW_POSES";
    case PivotStatus::kTooLittleRotation:
      return "TOO_LITTLE_ROTATION";
  }
  return "?";
}

PivotCalibrationResult CalibratePivot(std::span<const Rigid3d> reference_from_instrument,
                                      const PivotCalibrationOptions& options) {
  options.Check();
  PivotCalibrationResult result;
  result.poses = reference_from_instrument.size();
  if (result.poses < options.min_poses) return result;
  std::vector<Rigid3d> kept(reference_from_instrument.begin(), reference_from_instrument.end());
  std::vector<double> residuals;
  for (int fit = 0;; ++fit) {
    FitPivot(kept, result);
    residuals.clear();
    for (const Rigid3d& pose : kept) {
      residuals.push_back((pose * result.tip_in_instrument - result.pivot_in_reference).norm());
    }
    const double limit_mm = options.outlier_factor * result.rms_mm;
    const auto outlier = [&](double r) { return r > limit_mm; };
    const auto count = std::count_if(residuals.begin(), residuals.end(), outlier);
    if (options.outlier_factor <= 0.0 || fit >= options.max_refits || count == 0 ||
        kept.size() - static_cast<std::size_t>(count) < options.min_poses) {
      break;
    }
    std::vector<Rigid3d> inliers;
    for (std::size_t i = 0; i < kept.size(); ++i) {
      if (!outlier(residuals[i])) inliers.push_back(kept[i]);
    }
    kept = std::move(inliers);
  }
  result.outliers = result.poses - kept.size();
  result.max_residual_mm = *std::max_element(residuals.begin(), residuals.end());
  std::vector<Eigen::Vector3d> shafts;
  shafts.reserve(kept.size());
  for (const Rigid3d& pose : kept) {
    const Eigen::Vector3d shaft = -(pose.rotation * result.tip_in_instrument);
    shafts.push_back(shaft.norm() > 0.0 ? shaft.normalized() : Eigen::Vector3d::UnitZ());
  }
  result.angular_range_rad = LargestAngleRad(shafts);
  result.status = result.angular_range_rad < options.min_angular_range_rad
                      ? PivotStatus::kTooLittleRotation
                      : PivotStatus::kOk;
  return result;
}

}  // namespace tofnav
