// SPDX-License-Identifier: BSD-3-Clause
// Kabsch rigid fit of paired points.
#include "tofnav/core/rigid_fit.hpp"

#include <Eigen/SVD>
#include <cmath>

#include "tofnav/core/require.hpp"

namespace tofnav {

RigidFitResult FitRigid(std::span<const Eigen::Vector3d> source,
                        std::span<const Eigen::Vector3d> target) {
  Require(source.size() == target.size(), "FitRigid: source and target sizes differ");
  Require(source.size() >= 3, "FitRigid: needs at least 3 pairs");
  const double n = static_cast<double>(source.size());
  Eigen::Vector3d source_mean = Eigen::Vector3d::Zero(), target_mean = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < source.size(); ++i) {
    source_mean += source[i];
    target_mean += target[i];
  }
  source_mean /= n;
  target_mean /= n;
  Eigen::Matrix3d h = Eigen::Matrix3d::Zero();  // sum (s - s_mean)(t - t_mean)^T
  for (std::size_t i = 0; i < source.size(); ++i) {
    h += (source[i] - source_mean) * (target[i] - target_mean).transpose();
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  const Eigen::Matrix3d rotation = svd.matrixV() * d * svd.matrixU().transpose();
  RigidFitResult result;
  result.target_from_source =
      Rigid3d(Eigen::Quaterniond(rotation), target_mean - rotation * source_mean);
  result.singular_values = svd.singularValues();
  double sum2 = 0.0;
  result.residuals_mm.reserve(source.size());
  for (std::size_t i = 0; i < source.size(); ++i) {
    const double e = (result.target_from_source * source[i] - target[i]).norm();
    result.residuals_mm.push_back(e);
    sum2 += e * e;
  }
  result.fre_rms_mm = std::sqrt(sum2 / n);
  return result;
}

}  // namespace tofnav
