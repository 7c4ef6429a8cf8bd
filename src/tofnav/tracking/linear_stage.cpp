// SPDX-License-Identifier: BSD-3-Clause
// Range errors from a linear-stage recording: match, PnP on rays, line fit, delta (Eq. 1 data).
#include "tofnav/tracking/linear_stage.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <optional>

#include "tofnav/core/dense_solvers.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/markers/marker_centre.hpp"

namespace tofnav {
namespace {

struct PosedFrame {
  std::size_t frame = 0;
  std::vector<int> detection;  // per structure marker, -1 unseen
  Rigid3d ahat_from_structure;
};

std::optional<PosedFrame> PoseFrame(const StageFrame& frame, std::size_t index,
                                    const ToolGeometry& structure,
                                    const StageRangeErrorOptions& options) {
  const Points3d centres = MarkerCentres(frame.markers, structure.SurfaceToCentreMm());
  const ToolPoseResult matched = EstimateToolPose(centres, structure, options.pose);
  if (!matched.ahat_from_tool) return std::nullopt;
  Points3d markers, rays;
  for (std::size_t k = 0; k < matched.marker_detection.size(); ++k) {
    const int d = matched.marker_detection[k];
    if (d < 0) continue;
    markers.push_back(structure.markers_in_tool[k]);
    // The reference centroid's ray: unbiased by the illumination fall-off, its extra noise
    // averages out along the run's line.
    const DetectedMarker& marker = frame.markers[static_cast<std::size_t>(d)];
    const bool has_reference = marker.reference_ray_in_ahat.squaredNorm() > 0.0;
    rays.push_back(has_reference ? marker.reference_ray_in_ahat : marker.ray_in_ahat);
  }
  const RayPoseResult pnp =
      EstimatePoseFromRays(markers, rays, *matched.ahat_from_tool, options.ray_pose);
  if (!pnp.converged) return std::nullopt;
  return PosedFrame{index, matched.marker_detection, pnp.ahat_from_tool};
}

// Chordal mean of unit quaternions: the dominant eigenvector of sum q q^T.
Eigen::Quaterniond MeanRotation(const std::vector<PosedFrame>& posed) {
  Eigen::Matrix4d sum = Eigen::Matrix4d::Zero();
  for (const PosedFrame& p : posed) {
    const Eigen::Vector4d q = p.ahat_from_structure.rotation.coeffs();
    sum += q * q.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> eig(sum);
  return Eigen::Quaterniond(Eigen::Vector4d(eig.eigenvectors().col(3))).normalized();
}

}  // namespace

void StageRangeErrorOptions::Check() const {
  pose.Check();
  ray_pose.Check();
  Require(max_line_residual_mm > 0.0, "StageRangeErrorOptions::max_line_residual_mm must be > 0");
  Require(min_frames >= 2, "StageRangeErrorOptions::min_frames must be >= 2");
  Require(!known_speed_mm_per_s ||
              (std::isfinite(*known_speed_mm_per_s) && *known_speed_mm_per_s > 0.0),
          "StageRangeErrorOptions::known_speed_mm_per_s must be > 0");
}

StageRangeErrorResult MeasureMarkerRangeErrors(std::span<const StageFrame> frames,
                                               const ToolGeometry& structure,
                                               const StageRangeErrorOptions& options) {
  options.Check();
  structure.Check();
  std::vector<PosedFrame> posed;
  for (std::size_t f = 0; f < frames.size(); ++f) {
    if (std::optional<PosedFrame> p = PoseFrame(frames[f], f, structure, options))
      posed.push_back(*p);
  }
  Require(static_cast<int>(posed.size()) >= options.min_frames,
          "MeasureMarkerRangeErrors: only " + std::to_string(posed.size()) + " frames give a pose");
  StageRangeErrorResult result;
  // Line fit: x(t) = o + v t (constant speed) or the principal line through the positions.
  const auto n = static_cast<Eigen::Index>(posed.size());
  Eigen::MatrixXd design(n, 2);
  Eigen::MatrixXd positions(n, 3);
  // PnP's depth comes from the structure's image size: its noise grows as range^2, so frames are
  // weighted by 1 / range^4 (weighted least squares). Unweighted, the far frames' noise tilted
  // the line by ~0.1 mm/s per run, which f_rf then carried as a range-dependent bias.
  Eigen::VectorXd sqrt_weight(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const PosedFrame& p = posed[static_cast<std::size_t>(i)];
    design(i, 0) = 1.0;
    design(i, 1) = frames[p.frame].timestamp_s;
    positions.row(i) = p.ahat_from_structure.translation.transpose();
    const double range_m = 1e-3 * std::max(p.ahat_from_structure.translation.norm(), 1.0);
    sqrt_weight(i) = 1.0 / (range_m * range_m);
  }
  std::vector<Eigen::Vector3d> on_line(posed.size());
  if (options.constant_speed) {
    const Eigen::MatrixXd coefficients = (sqrt_weight.asDiagonal() * design)
                                             .colPivHouseholderQr()
                                             .solve(sqrt_weight.asDiagonal() * positions);
    result.line_origin_mm = coefficients.row(0).transpose();
    result.line_velocity_mm_per_s = coefficients.row(1).transpose();
    result.fitted_speed_mm_per_s = result.line_velocity_mm_per_s.norm();
    if (options.known_speed_mm_per_s && result.fitted_speed_mm_per_s > 0.0) {
      result.line_velocity_mm_per_s *= *options.known_speed_mm_per_s / result.fitted_speed_mm_per_s;
      // The origin that minimises the same weighted squares with the velocity fixed.
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      double total = 0.0;
      for (Eigen::Index i = 0; i < n; ++i) {
        const double w = sqrt_weight(i) * sqrt_weight(i);
        sum += w * (positions.row(i).transpose() - result.line_velocity_mm_per_s * design(i, 1));
        total += w;
      }
      result.line_origin_mm = sum / total;
    }
    for (Eigen::Index i = 0; i < n; ++i) {
      on_line[static_cast<std::size_t>(i)] =
          result.line_origin_mm + result.line_velocity_mm_per_s * design(i, 1);
    }
  } else {
    std::vector<Eigen::Vector3d> points(posed.size());
    for (Eigen::Index i = 0; i < n; ++i) points[static_cast<std::size_t>(i)] = positions.row(i);
    const PrincipalAxes principal = ComputePrincipalAxes(points);
    const Eigen::Vector3d mean = principal.centroid;
    const Eigen::MatrixXd centred = positions.rowwise() - mean.transpose();
    const Eigen::Vector3d direction = principal.axes.col(0);
    result.line_origin_mm = mean;
    result.line_velocity_mm_per_s = direction;
    for (Eigen::Index i = 0; i < n; ++i) {
      on_line[static_cast<std::size_t>(i)] =
          mean + direction * direction.dot(centred.row(i).transpose());
    }
  }
  result.ahat_from_structure_rotation = MeanRotation(posed);
  double sum2 = 0.0;
  for (std::size_t i = 0; i < posed.size(); ++i) {
    sum2 += (posed[i].ahat_from_structure.translation - on_line[i]).squaredNorm();
  }
  result.line_rms_mm = std::sqrt(sum2 / static_cast<double>(posed.size()));
  // Eq. (1) data: delta = measured surface range - the surface range of the reference centre.
  const double radius = structure.SurfaceToCentreMm();
  // Flat tape: each marker's entrance angle from the run's mean orientation (docs/tracking.md 4).
  const std::optional<Eigen::Vector3d> normal_in_ahat =
      structure.marker_type == MarkerType::kDisc
          ? std::optional<Eigen::Vector3d>(result.ahat_from_structure_rotation *
                                           MarkerPlaneNormal(structure))
          : std::nullopt;
  for (std::size_t i = 0; i < posed.size(); ++i) {
    if ((posed[i].ahat_from_structure.translation - on_line[i]).norm() >
        options.max_line_residual_mm) {
      continue;
    }
    ++result.frames_used;
    const Rigid3d reference(result.ahat_from_structure_rotation, on_line[i]);
    const StageFrame& frame = frames[posed[i].frame];
    for (std::size_t k = 0; k < posed[i].detection.size(); ++k) {
      const int d = posed[i].detection[k];
      if (d < 0) continue;
      const DetectedMarker& marker = frame.markers[static_cast<std::size_t>(d)];
      const double true_centre_mm = (reference * structure.markers_in_tool[k]).norm();
      const double true_surface_mm = SurfaceRangeForCentreMm(marker, radius, true_centre_mm);
      const double entrance_rad =
          normal_in_ahat ? TapeEntranceAngleRad(*normal_in_ahat, marker.ray_in_ahat) : 0.0;
      result.samples.push_back(
          {marker.surface_range_mm, marker.surface_range_mm - true_surface_mm, 1.0, entrance_rad});
      result.sample_frame.push_back(static_cast<int>(posed[i].frame));
      result.sample_marker.push_back(static_cast<int>(k));
    }
  }
  return result;
}

}  // namespace tofnav
