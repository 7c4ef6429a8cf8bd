// SPDX-License-Identifier: BSD-3-Clause
// A frame against the fused model: residuals, bounded point-to-plane alignment, verdict.
#include "tofnav/fusion/model_check.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "tofnav/core/dense_solvers.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/core/rotation_vector.hpp"
#include "tofnav/fusion/tsdf_sample.hpp"

namespace tofnav {
namespace {

// Gradients flatter than this are the truncated plateau, not a surface (the distance field's
// gradient is ~1 at the surface, larger at grazing incidence: the distance is along the rays).
constexpr double kMinGradient = 0.3;
// Weight of the prior on the correction: (range noise ~1 mm / tracking error at the surface
// ~0.5 mm)^2 (docs/tracking.md), against one point's weight of 1.
constexpr double kPriorWeight = 4.0;

struct Residuals {
  std::size_t points = 0;             // on the model
  std::vector<Eigen::Vector3d> q, n;  // inliers: points in `tool`, unit normals
  std::vector<double> r;              // point-to-plane distances [mm]
};

Residuals Evaluate(TsdfReader& reader, const std::vector<Eigen::Vector3d>& points_in_ahat,
                   const Rigid3d& tool_from_ahat, const ModelCheckOptions& options,
                   double band_mm) {
  Residuals out;
  for (const Eigen::Vector3d& p : points_in_ahat) {
    const Eigen::Vector3d q = tool_from_ahat * p;
    const std::optional<TsdfSample> s = reader.Sample(q, options.min_model_weight);
    if (!s) continue;
    ++out.points;
    const double g = s->gradient.norm();
    if (!(g >= kMinGradient) || std::abs(s->distance_mm) >= band_mm) continue;
    out.q.push_back(q);
    out.n.push_back(s->gradient / g);
    out.r.push_back(s->distance_mm / g);
  }
  return out;
}

double MedianAbs(const std::vector<double>& values) {
  if (values.empty()) return 0.0;
  std::vector<double> a(values.size());
  std::transform(values.begin(), values.end(), a.begin(), [](double v) { return std::abs(v); });
  const auto mid = a.begin() + static_cast<std::ptrdiff_t>(a.size() / 2);
  std::nth_element(a.begin(), mid, a.end());
  return *mid;
}

// The RMS distance of the inliers from the centre, plus 1 mm (never 0) [mm].
double RmsRadius(const Residuals& res, const Eigen::Vector3d& centre) {
  double sum = 0.0;
  for (const Eigen::Vector3d& q : res.q) sum += (q - centre).squaredNorm();
  return std::sqrt(sum / static_cast<double>(std::max<std::size_t>(res.q.size(), 1))) + 1.0;
}

// The correction as x = (radius * rotation vector, translation of the centre) [mm].
Rigid3d FromParameters(const Vector6d& x, const Eigen::Vector3d& centre, double radius) {
  const Eigen::Quaterniond rotation = FromRotationVector(x.head<3>() / radius);
  return {rotation, centre + x.tail<3>() - rotation * centre};
}

// One Gauss-Newton step of the correction x (rotation about `centre`, scaled by the points' RMS
// radius so that both parts are millimetres of motion at the points, and translation) that
// moves the inliers onto the model, with a prior pulling x to 0: the tracked pose is known to
// ~0.5 mm at the surface, so directions the surface does not constrain (sliding over a
// sphere-like cap) stay where tracking put them instead of drifting with the noise.
Vector6d AlignmentStep(const Residuals& res, const Eigen::Vector3d& centre, double radius,
                       const Vector6d& x, double huber_mm) {
  Eigen::Matrix<double, 6, 6> a = Eigen::Matrix<double, 6, 6>::Zero();
  Vector6d b = Vector6d::Zero();
  for (std::size_t i = 0; i < res.r.size(); ++i) {
    Vector6d j;
    j << (res.q[i] - centre).cross(res.n[i]) / radius, res.n[i];
    const double w = std::abs(res.r[i]) <= huber_mm ? 1.0 : huber_mm / std::abs(res.r[i]);
    a += w * j * j.transpose();
    b -= w * res.r[i] * j;
  }
  a.diagonal().array() += kPriorWeight;
  b -= kPriorWeight * x;
  return x + SolveSymmetric(a, b);
}

Eigen::Vector3d Centroid(const std::vector<Eigen::Vector3d>& points) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) sum += p;
  return sum / static_cast<double>(std::max<std::size_t>(points.size(), 1));
}

}  // namespace

void ModelCheckOptions::Check() const {
  Require(warmup_frames >= 1, "ModelCheckOptions::warmup_frames must be >= 1");
  Require(std::isfinite(min_model_weight) && min_model_weight > 0.0,
          "ModelCheckOptions::min_model_weight must be > 0");
  Require(pixel_stride >= 1, "ModelCheckOptions::pixel_stride must be >= 1");
  Require(min_points >= 6, "ModelCheckOptions::min_points must be >= 6");
  Require(inlier_band > 0.0 && inlier_band <= 1.0, "ModelCheckOptions::inlier_band in (0, 1]");
  Require(min_inlier_fraction >= 0.0 && min_inlier_fraction <= 1.0,
          "ModelCheckOptions::min_inlier_fraction must be in [0, 1]");
  Require(max_median_residual_mm > 0.0, "ModelCheckOptions::max_median_residual_mm must be > 0");
  Require(max_correction_mm > 0.0 && max_correction_rad > 0.0,
          "ModelCheckOptions::max_correction_mm and max_correction_rad must be > 0");
  Require(min_correction_mm >= 0.0 && min_correction_rad >= 0.0,
          "ModelCheckOptions::min_correction_mm and min_correction_rad must be >= 0");
  Require(iterations >= 1 && iterations <= 50, "ModelCheckOptions::iterations in [1, 50]");
  Require(huber_mm > 0.0, "ModelCheckOptions::huber_mm must be > 0");
  Require(gate_mm > 0.0, "ModelCheckOptions::gate_mm must be > 0");
}

const char* ToString(ModelVerdict verdict) {
  switch (verdict) {
    case ModelVerdict::kUnchecked:
      return "unchecked";
    case ModelVerdict::kAccepted:
      return "accepted";
    case ModelVerdict::kRefined:
      return "refined";
    case ModelVerdict::kRejectedResidual:
      return "model_residual";
    case ModelVerdict::kRejectedOffset:
      return "model_offset";
  }
  return "unknown";
}

ModelCheckResult CheckFrameAgainstModel(const TsdfVolume& volume, const Image<float>& range_mm,
                                        const AhatCamera& camera, const Rigid3d& tool_from_ahat,
                                        const ModelCheckOptions& options) {
  options.Check();
  Require(range_mm.width() == camera.width() && range_mm.height() == camera.height(),
          "CheckFrameAgainstModel: the range image must have the camera's size");
  ModelCheckResult result;
  result.tool_from_ahat = tool_from_ahat;
  const TsdfOptions& tsdf = volume.options();
  std::vector<Eigen::Vector3d> points;  // sampled points in `ahat`
  for (int v = 0; v < camera.height(); v += options.pixel_stride) {
    for (int u = 0; u < camera.width(); u += options.pixel_stride) {
      const float r = range_mm(u, v);
      if (!(r >= tsdf.min_range_mm && r <= tsdf.max_range_mm) || !camera.IsValid(u, v)) continue;
      points.push_back(static_cast<double>(r) * camera.PixelRay(u, v).cast<double>());
    }
  }
  TsdfReader reader(volume);
  const double band_mm = options.inlier_band * tsdf.truncation_mm();
  Residuals res = Evaluate(reader, points, tool_from_ahat, options, band_mm);
  result.points = res.points;
  result.inliers = res.r.size();
  result.median_residual_mm = result.median_residual_after_mm = MedianAbs(res.r);
  if (!options.enabled || res.points < options.min_points) return result;
  const auto too_few = [&](const Residuals& x) {
    return static_cast<double>(x.r.size()) <
           options.min_inlier_fraction * static_cast<double>(x.points);
  };
  if (too_few(res)) {
    result.verdict = ModelVerdict::kRejectedResidual;
    return result;
  }
  const Eigen::Vector3d centre = Centroid(res.q);
  const double radius = RmsRadius(res, centre);
  Vector6d x = Vector6d::Zero();
  Rigid3d correction;  // refined_tool_from_tool
  for (int it = 0; it < options.iterations; ++it) {
    x = AlignmentStep(res, centre, radius, x, options.huber_mm);
    correction = FromParameters(x, centre, radius);
    result.correction_mm = x.tail<3>().norm();
    result.correction_rad = x.head<3>().norm() / radius;
    // Far beyond the bound already: no need to converge to know the verdict.
    if (result.correction_mm > 2.0 * options.max_correction_mm ||
        result.correction_rad > 2.0 * options.max_correction_rad) {
      break;
    }
    res = Evaluate(reader, points, correction * tool_from_ahat, options, band_mm);
    if (res.r.size() < 6) break;
  }
  result.correction = correction;
  result.inliers = res.r.size();
  result.median_residual_after_mm = MedianAbs(res.r);
  if (result.correction_mm > options.max_correction_mm ||
      result.correction_rad > options.max_correction_rad) {
    result.verdict = ModelVerdict::kRejectedOffset;
  } else if (too_few(res) || result.median_residual_after_mm > options.max_median_residual_mm) {
    result.verdict = ModelVerdict::kRejectedResidual;
  } else if (options.refine && (result.correction_mm >= options.min_correction_mm ||
                                result.correction_rad >= options.min_correction_rad)) {
    result.verdict = ModelVerdict::kRefined;
    result.tool_from_ahat = correction * tool_from_ahat;
  } else {
    result.verdict = ModelVerdict::kAccepted;
  }
  return result;
}

}  // namespace tofnav
