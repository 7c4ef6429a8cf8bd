// SPDX-License-Identifier: BSD-3-Clause
// Paired-point registration (core FitRigid) and the Fitzpatrick FRE/TRE relations.
#include "tofnav/registration/paired_points.hpp"

#include <cmath>
#include <utility>

#include "tofnav/core/dense_solvers.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/core/rigid_fit.hpp"

namespace tofnav {
namespace {

// Relative second spread of the centred points; the spreads come from the scatter matrix, whose
// rounding leaves ~1e-8 of the largest on exactly collinear points.
constexpr double kCollinear = 1e-6;

Eigen::Matrix3Xd ToMatrix(std::span<const Eigen::Vector3d> points) {
  Eigen::Matrix3Xd m(3, static_cast<Eigen::Index>(points.size()));
  for (std::size_t i = 0; i < points.size(); ++i) m.col(static_cast<Eigen::Index>(i)) = points[i];
  return m;
}

}  // namespace

PairedPointResult RegisterPairedPoints(std::span<const Eigen::Vector3d> source,
                                       std::span<const Eigen::Vector3d> target) {
  Require(source.size() == target.size(), "RegisterPairedPoints: point counts differ");
  Require(source.size() >= 3, "RegisterPairedPoints: needs at least 3 pairs");
  const Eigen::Matrix3Xd s = ToMatrix(source);
  const Eigen::Matrix3Xd t = ToMatrix(target);
  Require(s.allFinite() && t.allFinite(), "RegisterPairedPoints: points must be finite");
  const Eigen::Vector3d spread = ComputePrincipalAxes(source).spreads;
  Require(spread(1) > kCollinear * std::max(spread(0), 1e-300),
          "RegisterPairedPoints: the source points are collinear");
  // Kabsch / Umeyama without scaling, shared with tool tracking.
  RigidFitResult fit = FitRigid(source, target);
  return {fit.target_from_source, fit.fre_rms_mm, std::move(fit.residuals_mm)};
}

double PredictFiducialTreMm(std::span<const Eigen::Vector3d> fiducials, double fle_rms_mm,
                            const Eigen::Vector3d& target) {
  Require(fiducials.size() >= 3, "PredictFiducialTreMm: needs at least 3 fiducials");
  Require(fle_rms_mm >= 0.0, "PredictFiducialTreMm: fle_rms_mm must be >= 0");
  const Eigen::Matrix3Xd f = ToMatrix(fiducials);
  const Eigen::Vector3d centroid = f.rowwise().mean();
  const Eigen::Matrix3Xd centred = f.colwise() - centroid;
  const auto n = static_cast<double>(fiducials.size());
  const auto axes = DecomposeSymmetric(Eigen::Matrix3d(centred * centred.transpose() / n));
  const Eigen::Vector3d offset = target - centroid;
  double sum = 0.0;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d axis = axes.vectors.col(k);
    // Squared distances from principal axis k: |x|^2 - (x . axis)^2.
    const double f_sq =
        (centred.colwise().squaredNorm().array() - (axis.transpose() * centred).array().square())
            .mean();
    const double d_sq = offset.squaredNorm() - std::pow(offset.dot(axis), 2);
    Require(f_sq > 0.0, "PredictFiducialTreMm: the fiducials are collinear");
    sum += d_sq / f_sq;
  }
  return fle_rms_mm * std::sqrt((1.0 + sum / 3.0) / n);
}

double EstimateFleFromFreMm(double fre_rms_mm, std::size_t fiducial_count) {
  Require(fiducial_count >= 3, "EstimateFleFromFreMm: needs at least 3 fiducials");
  return fre_rms_mm / std::sqrt(1.0 - 2.0 / static_cast<double>(fiducial_count));
}

}  // namespace tofnav
