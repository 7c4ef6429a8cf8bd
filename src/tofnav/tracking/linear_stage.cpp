// SPDX-License-Identifier: BSD-3-Clause
// Range errors from a linear-stage recording: match, PnP on rays, line fit, delta (Eq. 1 data).
#include "tofnav/tracking/linear_stage.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <optional>

#include "tofnav/core/dense_solvers.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/core/rotation_vector.hpp"
#include "tofnav/markers/marker_centre.hpp"

namespace tofnav {
namespace {

struct PosedFrame {
  std::size_t frame = 0;
  std::vector<int> detection;  // per structure marker, -1 unseen
  Rigid3d ahat_from_structure;
  Points3d markers, rays;  // the seen markers in `structure` and their reference rays
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
  return PosedFrame{index, matched.marker_detection, pnp.ahat_from_tool, std::move(markers),
                    std::move(rays)};
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

// The structure's one rotation and constant-speed trajectory over a run: x(t) = R m + o + v t.
struct RunLine {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  // at the run's mean time
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
};

// Fits R, o and (when fit_velocity) v to every marker ray of the run at once: Gauss-Newton on
// the sum of |(I - r r^T) x|^2 / |x|^2, each ray's squared angle to its marker (docs/tracking.md
// 4, "the stage reference"). Posed frame by frame, PnP's depth is biased where its tilt is
// uncertain: it fits the structure's foreshortened size, so a tilt error e shortens the range by
// about d e^2 / 2, and near a frontal view e is degrees (0.2 mm too near at 0-10 deg, 0.04 mm too
// far at 30 deg over the suite's stages). The run's rotation does not change, and one rotation
// fitted to all its frames errs by a tenth of a degree. times_s are relative to the mean time.
void RefineRunLine(const std::vector<PosedFrame>& posed, std::span<const double> times_s,
                   bool fit_velocity, RunLine& line) {
  constexpr int kMaxIterations = 30;
  constexpr double kSettledMm = 1e-7;  // step at the structure's size
  using Matrix9d = Eigen::Matrix<double, 9, 9>;
  using Vector9d = Eigen::Matrix<double, 9, 1>;
  const Eigen::Index unknowns = fit_velocity ? 9 : 6;
  double lever_mm = 1.0;
  for (const PosedFrame& p : posed) {
    for (const Eigen::Vector3d& m : p.markers) lever_mm = std::max(lever_mm, m.norm());
  }
  for (int iteration = 0; iteration < kMaxIterations; ++iteration) {
    Matrix9d h = Matrix9d::Zero();
    Vector9d g = Vector9d::Zero();
    for (std::size_t i = 0; i < posed.size(); ++i) {
      for (std::size_t k = 0; k < posed[i].markers.size(); ++k) {
        const Eigen::Vector3d rm = line.rotation * posed[i].markers[k];
        const Eigen::Vector3d x = rm + line.origin + line.velocity * times_s[i];
        const Eigen::Vector3d& r = posed[i].rays[k];
        const Eigen::Matrix3d w =
            (Eigen::Matrix3d::Identity() - r * r.transpose()) / x.squaredNorm();
        Eigen::Matrix<double, 3, 9> j;
        j.leftCols<6>() = PoseJacobian(rm);
        j.rightCols<3>() = times_s[i] * Eigen::Matrix3d::Identity();
        const Eigen::Matrix<double, 9, 3> jw = j.transpose() * w;
        h += jw * j;
        g += jw * x;
      }
    }
    const Eigen::VectorXd step =
        -h.topLeftCorner(unknowns, unknowns).ldlt().solve(g.head(unknowns));
    if (!step.allFinite()) return;
    line.rotation = FromRotationVector(step.head<3>()).toRotationMatrix() * line.rotation;
    line.origin += step.segment<3>(3);
    if (fit_velocity) line.velocity += step.tail<3>();
    if (step.head<3>().norm() * lever_mm + step.tail(unknowns - 3).norm() < kSettledMm) return;
  }
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
    // The weighted line through the per-frame positions starts the fit over all rays at once.
    const double mean_time_s = design.col(1).mean();
    std::vector<double> times_s(posed.size());
    for (Eigen::Index i = 0; i < n; ++i)
      times_s[static_cast<std::size_t>(i)] = design(i, 1) - mean_time_s;
    RunLine line;
    line.rotation = MeanRotation(posed).toRotationMatrix();
    line.velocity = coefficients.row(1).transpose();
    line.origin = coefficients.row(0).transpose() + line.velocity * mean_time_s;
    RefineRunLine(posed, times_s, true, line);
    result.fitted_speed_mm_per_s = line.velocity.norm();
    if (options.known_speed_mm_per_s && result.fitted_speed_mm_per_s > 0.0) {
      line.velocity *= *options.known_speed_mm_per_s / result.fitted_speed_mm_per_s;
      RefineRunLine(posed, times_s, false, line);  // the origin and rotation at that speed
    }
    result.ahat_from_structure_rotation = Eigen::Quaterniond(line.rotation).normalized();
    result.line_velocity_mm_per_s = line.velocity;
    result.line_origin_mm = line.origin - line.velocity * mean_time_s;
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
    result.ahat_from_structure_rotation = MeanRotation(posed);
    for (Eigen::Index i = 0; i < n; ++i) {
      on_line[static_cast<std::size_t>(i)] =
          mean + direction * direction.dot(centred.row(i).transpose());
    }
  }
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
