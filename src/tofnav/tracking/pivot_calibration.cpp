// SPDX-License-Identifier: BSD-3-Clause
// CalibratePivot: normal equations of the stacked pivot constraints (docs/tracking.md, "Pivot
// calibration").
#include "tofnav/tracking/pivot_calibration.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

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

}  // namespace

void PivotCalibrationOptions::Check() const {
  Require(min_poses >= 3, "PivotCalibrationOptions.min_poses must be >= 3");
  Require(std::isfinite(min_angular_range_rad) && min_angular_range_rad >= 0.0,
          "PivotCalibrationOptions.min_angular_range_rad must be >= 0");
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
  // Each pose: [R_i  -I] [tip; pivot] = -t_i. Normal equations A^T A x = A^T b, with
  // R_i^T R_i = I, so A^T A = sum [[I, -R_i^T], [-R_i, I]].
  Eigen::Matrix<double, 6, 6> normal = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> rhs = Eigen::Matrix<double, 6, 1>::Zero();
  for (const Rigid3d& pose : reference_from_instrument) {
    const Eigen::Matrix3d r = pose.RotationMatrix();
    normal.topLeftCorner<3, 3>() += Eigen::Matrix3d::Identity();
    normal.topRightCorner<3, 3>() -= r.transpose();
    normal.bottomLeftCorner<3, 3>() -= r;
    normal.bottomRightCorner<3, 3>() += Eigen::Matrix3d::Identity();
    rhs.head<3>() -= r.transpose() * pose.translation;
    rhs.tail<3>() += pose.translation;
  }
  const Eigen::Matrix<double, 6, 1> x = normal.ldlt().solve(rhs);
  result.tip_in_instrument = x.head<3>();
  result.pivot_in_reference = x.tail<3>();
  double sum_sq = 0.0;
  std::vector<Eigen::Vector3d> shafts;
  shafts.reserve(result.poses);
  for (const Rigid3d& pose : reference_from_instrument) {
    const double residual = (pose * result.tip_in_instrument - result.pivot_in_reference).norm();
    sum_sq += residual * residual;
    result.max_residual_mm = std::max(result.max_residual_mm, residual);
    const Eigen::Vector3d shaft = -(pose.rotation * result.tip_in_instrument);
    shafts.push_back(shaft.norm() > 0.0 ? shaft.normalized() : Eigen::Vector3d::UnitZ());
  }
  result.rms_mm = std::sqrt(sum_sq / static_cast<double>(result.poses));
  result.angular_range_rad = LargestAngleRad(shafts);
  result.status = result.angular_range_rad < options.min_angular_range_rad
                      ? PivotStatus::kTooLittleRotation
                      : PivotStatus::kOk;
  return result;
}

}  // namespace tofnav
