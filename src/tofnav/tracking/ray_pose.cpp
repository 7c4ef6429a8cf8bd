// SPDX-License-Identifier: BSD-3-Clause
// Pose on unit rays by Gauss-Newton: collinearity error, optionally with weighted ranges.
#include "tofnav/tracking/ray_pose.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <vector>

#include "tofnav/core/dense_solvers.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/core/rotation_vector.hpp"

namespace tofnav {
namespace {

// Normal equations of sum (x_i - c_i)^T W_i (x_i - c_i), x_i = R m_i + t, in (w, t) with
// R <- Exp(w) R: dx/dw = -[R m]x, dx/dt = I. Adds to h = J^T W J and g = J^T W e.
void AddNormalEquations(std::span<const Eigen::Vector3d> markers,
                        std::span<const Eigen::Vector3d> targets,
                        std::span<const Eigen::Matrix3d> weights, const Eigen::Matrix3d& rotation,
                        const Eigen::Vector3d& translation, Matrix6d& h, Vector6d& g) {
  for (std::size_t i = 0; i < markers.size(); ++i) {
    const Eigen::Vector3d rm = rotation * markers[i];
    const Eigen::Matrix<double, 3, 6> j = PoseJacobian(rm);
    const Eigen::Matrix<double, 6, 3> jw = j.transpose() * weights[i];
    h += jw * j;
    g += jw * (rm + translation - targets[i]);
  }
}

// Minimises sum (x_i - c_i)^T W_i (x_i - c_i) (AddNormalEquations) by Gauss-Newton from
// `initial`. W_i = I - r r^T with c_i = 0 is the collinearity error.
RayPoseResult WeightedGaussNewton(std::span<const Eigen::Vector3d> markers,
                                  std::span<const Eigen::Vector3d> targets,
                                  std::span<const Eigen::Matrix3d> weights, const Rigid3d& initial,
                                  const RayPoseOptions& options) {
  RayPoseResult result;
  Eigen::Matrix3d rotation = initial.RotationMatrix();
  Eigen::Vector3d translation = initial.translation;
  double max_lever_mm = 0.0;
  for (const Eigen::Vector3d& m : markers) max_lever_mm = std::max(max_lever_mm, m.norm());
  for (result.iterations = 1; result.iterations <= options.max_iterations; ++result.iterations) {
    Matrix6d h = Matrix6d::Zero();
    Vector6d g = Vector6d::Zero();
    AddNormalEquations(markers, targets, weights, rotation, translation, h, g);
    const Vector6d step = -SolveSymmetric(h, g);
    if (!step.allFinite()) break;
    const Eigen::Vector3d w = step.head<3>();
    rotation = FromRotationVector(w).toRotationMatrix() * rotation;
    translation += step.tail<3>();
    if (step.tail<3>().norm() + w.norm() * max_lever_mm < options.tolerance_mm) {
      result.converged = true;
      break;
    }
  }
  result.ahat_from_tool = Rigid3d(Eigen::Quaterniond(rotation), translation);
  return result;
}

// Sets rms_ray_distance_mm: RMS of |(I - r r^T) x_i| at the result's pose.
void SetRayDistance(std::span<const Eigen::Vector3d> markers,
                    std::span<const Eigen::Matrix3d> off_ray, RayPoseResult& result) {
  double sum2 = 0.0;
  for (std::size_t i = 0; i < markers.size(); ++i) {
    sum2 += (off_ray[i] * (result.ahat_from_tool * markers[i])).squaredNorm();
  }
  result.rms_ray_distance_mm = std::sqrt(sum2 / static_cast<double>(markers.size()));
}

Eigen::Matrix3d OffRay(const Eigen::Vector3d& ray) {
  const Eigen::Vector3d r = ray.normalized();
  return Eigen::Matrix3d::Identity() - r * r.transpose();
}

// Per observation: the weight (I - r r^T) / s_lat^2 + r r^T / s_range^2 and the centre r d.
void ObservationWeights(std::span<const RayRangeObservation> observations,
                        std::vector<Eigen::Matrix3d>& weight,
                        std::vector<Eigen::Vector3d>& centre) {
  weight.resize(observations.size());
  centre.resize(observations.size());
  for (std::size_t i = 0; i < observations.size(); ++i) {
    const RayRangeObservation& o = observations[i];
    Require(o.lateral_sigma_mm > 0.0 && o.range_sigma_mm > 0.0,
            "EstimatePoseFromRaysAndRanges: sigmas must be > 0");
    const Eigen::Vector3d r = o.ray_in_ahat.normalized();
    centre[i] = r * o.range_mm;
    weight[i] = OffRay(r) / (o.lateral_sigma_mm * o.lateral_sigma_mm) +
                r * r.transpose() / (o.range_sigma_mm * o.range_sigma_mm);
  }
}

}  // namespace

Eigen::Matrix<double, 3, 6> PoseJacobian(const Eigen::Vector3d& rotated_point) {
  const Eigen::Vector3d& p = rotated_point;
  Eigen::Matrix<double, 3, 6> j;
  j.leftCols<3>() << 0, p.z(), -p.y(), -p.z(), 0, p.x(), p.y(), -p.x(), 0;
  j.rightCols<3>().setIdentity();
  return j;
}

void RayPoseOptions::Check() const {
  Require(max_iterations >= 1, "RayPoseOptions::max_iterations must be >= 1");
  Require(tolerance_mm > 0.0, "RayPoseOptions::tolerance_mm must be > 0");
}

RayPoseResult EstimatePoseFromRays(std::span<const Eigen::Vector3d> markers_in_tool,
                                   std::span<const Eigen::Vector3d> rays_in_ahat,
                                   const Rigid3d& initial_ahat_from_tool,
                                   const RayPoseOptions& options) {
  options.Check();
  const std::size_t n = markers_in_tool.size();
  Require(n >= 3 && rays_in_ahat.size() == n, "EstimatePoseFromRays: needs >= 3 marker-ray pairs");
  std::vector<Eigen::Matrix3d> off_ray(n);  // I - r r^T: the part of a point off its ray
  for (std::size_t i = 0; i < n; ++i) off_ray[i] = OffRay(rays_in_ahat[i]);
  const std::vector<Eigen::Vector3d> origin(n, Eigen::Vector3d::Zero());
  RayPoseResult result =
      WeightedGaussNewton(markers_in_tool, origin, off_ray, initial_ahat_from_tool, options);
  SetRayDistance(markers_in_tool, off_ray, result);
  return result;
}

RayPoseResult EstimatePoseFromRaysAndRanges(std::span<const Eigen::Vector3d> markers_in_tool,
                                            std::span<const RayRangeObservation> observations,
                                            const Rigid3d& initial_ahat_from_tool,
                                            const RayPoseOptions& options) {
  options.Check();
  const std::size_t n = markers_in_tool.size();
  Require(n >= 3 && observations.size() == n,
          "EstimatePoseFromRaysAndRanges: needs >= 3 marker-observation pairs");
  std::vector<Eigen::Matrix3d> off_ray(n), weight;
  std::vector<Eigen::Vector3d> centre;
  for (std::size_t i = 0; i < n; ++i) off_ray[i] = OffRay(observations[i].ray_in_ahat);
  ObservationWeights(observations, weight, centre);
  RayPoseResult result =
      WeightedGaussNewton(markers_in_tool, centre, weight, initial_ahat_from_tool, options);
  SetRayDistance(markers_in_tool, off_ray, result);
  return result;
}

Eigen::Matrix<double, 6, 6> RayRangePoseCovariance(
    std::span<const Eigen::Vector3d> markers_in_tool,
    std::span<const RayRangeObservation> observations, const Rigid3d& ahat_from_tool) {
  Require(markers_in_tool.size() >= 3 && observations.size() == markers_in_tool.size(),
          "RayRangePoseCovariance: needs >= 3 marker-observation pairs");
  std::vector<Eigen::Matrix3d> weight;
  std::vector<Eigen::Vector3d> centre;
  ObservationWeights(observations, weight, centre);
  Matrix6d h = Matrix6d::Zero();
  Vector6d g = Vector6d::Zero();
  AddNormalEquations(markers_in_tool, centre, weight, ahat_from_tool.RotationMatrix(),
                     ahat_from_tool.translation, h, g);
  return InvertSymmetric(h);
}

}  // namespace tofnav
