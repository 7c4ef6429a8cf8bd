// SPDX-License-Identifier: BSD-3-Clause
// Reference plane fit, the paper's per-point depth error and the per-material summaries.
#include "tofnav/correction/material_study.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <tuple>
#include <utility>

#include "tofnav/core/dense_solvers.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/markers/marker_centre.hpp"

namespace tofnav {
namespace {

constexpr double kMinRayPlaneCosine = 1e-6;  // |n . X| / ||X|| below this: ray along the plane
constexpr double kMadToSigma = 1.4826;

// Least-squares plane through the points flagged in `use`.
std::optional<ReferencePlane> FitPlane(std::span<const Eigen::Vector3d> points,
                                       const std::vector<bool>& use) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  int n = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (use[i]) mean += points[i], ++n;
  }
  if (n < 3) return std::nullopt;
  mean /= n;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (use[i]) cov += (points[i] - mean) * (points[i] - mean).transpose();
  }
  const auto eig = DecomposeSymmetric(cov);
  ReferencePlane plane;
  plane.normal = eig.vectors.col(0);
  plane.offset_mm = -plane.normal.dot(mean);
  if (plane.offset_mm < 0.0) plane.normal = -plane.normal, plane.offset_mm = -plane.offset_mm;
  plane.inliers = n;
  plane.rms_mm = std::sqrt(std::max(0.0, eig.values(0)) / n);
  return plane;
}

double Median(std::vector<double>& values) {
  const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  return *mid;
}

// Summaries of the pixels grouped by key(pixel) -> (depth bin, angle bin); -1: the whole axis.
template <typename Key>
std::vector<MaterialCell> Group(const std::vector<MaterialPixel>& pixels,
                                const MaterialStudyOptions& options, Key key) {
  std::map<std::tuple<int, int, int>, std::pair<std::vector<float>, std::vector<float>>> groups;
  for (const MaterialPixel& p : pixels) {
    const auto [depth_bin, angle_bin] = key(p);
    auto& [reference, truth] = groups[{p.material, depth_bin, angle_bin}];
    reference.push_back(p.error_vs_reference_mm);
    truth.push_back(p.error_vs_truth_mm);
  }
  constexpr double kInf = std::numeric_limits<double>::infinity();
  std::vector<MaterialCell> cells;
  for (auto& [k, errors] : groups) {
    const auto [material, depth_bin, angle_bin] = k;
    MaterialCell cell;
    cell.material = material;
    cell.depth_min_mm = depth_bin < 0 ? 0.0 : depth_bin * options.depth_bin_mm;
    cell.depth_max_mm = depth_bin < 0 ? kInf : (depth_bin + 1) * options.depth_bin_mm;
    cell.angle_min_rad = angle_bin < 0 ? 0.0 : angle_bin * options.angle_bin_rad;
    cell.angle_max_rad = angle_bin < 0 ? kInf : (angle_bin + 1) * options.angle_bin_rad;
    cell.vs_reference_mm = SummariseDepthErrors(std::move(errors.first));
    cell.vs_truth_mm = SummariseDepthErrors(std::move(errors.second));
    cells.push_back(cell);
  }
  return cells;
}

}  // namespace

void ReferencePlaneOptions::Check() const {
  Require(iterations >= 1, "ReferencePlaneOptions::iterations must be >= 1");
  Require(outlier_mad_factor > 0.0, "ReferencePlaneOptions::outlier_mad_factor must be > 0");
  Require(min_outlier_mm >= 0.0, "ReferencePlaneOptions::min_outlier_mm must be >= 0");
  Require(min_points >= 3, "ReferencePlaneOptions::min_points must be >= 3");
}

std::optional<ReferencePlane> FitReferencePlane(std::span<const Eigen::Vector3d> points_in_ahat,
                                                const ReferencePlaneOptions& options) {
  options.Check();
  if (points_in_ahat.size() < static_cast<std::size_t>(options.min_points)) return std::nullopt;
  std::vector<bool> use(points_in_ahat.size(), true);
  std::optional<ReferencePlane> plane = FitPlane(points_in_ahat, use);
  std::vector<double> distances(points_in_ahat.size());
  for (int it = 1; it < options.iterations && plane; ++it) {
    for (std::size_t i = 0; i < points_in_ahat.size(); ++i) {
      distances[i] = std::abs(plane->normal.dot(points_in_ahat[i]) + plane->offset_mm);
    }
    std::vector<double> copy = distances;
    const double limit =
        std::max(options.min_outlier_mm, options.outlier_mad_factor * kMadToSigma * Median(copy));
    for (std::size_t i = 0; i < distances.size(); ++i) use[i] = distances[i] <= limit;
    plane = FitPlane(points_in_ahat, use);
  }
  if (!plane || plane->inliers < options.min_points) return std::nullopt;
  return plane;
}

std::optional<double> ReferenceDepthErrorMm(const ReferencePlane& plane,
                                            const Eigen::Vector3d& point_in_ahat) {
  const double norm = point_in_ahat.norm();
  const double n_dot_x = plane.normal.dot(point_in_ahat);
  if (!(norm > 0.0) || std::abs(n_dot_x) < kMinRayPlaneCosine * norm) return std::nullopt;
  const double k = 1.0 + plane.offset_mm / n_dot_x;  // (1 - k) n.X + D = 0
  return k * norm;
}

double PlaneIncidenceRad(const ReferencePlane& plane, const Eigen::Vector3d& point_in_ahat) {
  return TapeEntranceAngleRad(plane.normal, point_in_ahat);
}

void MaterialStudyOptions::Check() const {
  Require(depth_bin_mm > 0.0, "MaterialStudyOptions::depth_bin_mm must be > 0");
  Require(angle_bin_rad > 0.0, "MaterialStudyOptions::angle_bin_rad must be > 0");
}

MaterialStudy::MaterialStudy(std::vector<std::string> materials, MaterialStudyOptions options)
    : materials_(std::move(materials)), options_(options) {
  options_.Check();
}

void MaterialStudy::Add(const MaterialPixel& pixel) {
  Require(pixel.material >= 0 && pixel.material < static_cast<int>(materials_.size()),
          "MaterialStudy::Add: material index out of range");
  pixels_.push_back(pixel);
}

MaterialStudyResult MaterialStudy::Summarise() const {
  const auto depth_bin = [&](const MaterialPixel& p) {
    return static_cast<int>(std::floor(p.reference_range_mm / options_.depth_bin_mm));
  };
  const auto angle_bin = [&](const MaterialPixel& p) {
    return static_cast<int>(std::floor(p.incidence_rad / options_.angle_bin_rad));
  };
  MaterialStudyResult result;
  result.materials = materials_;
  result.overall = Group(pixels_, options_, [](const MaterialPixel&) { return std::pair{-1, -1}; });
  result.by_depth = Group(pixels_, options_, [&](const MaterialPixel& p) {
    return std::pair{depth_bin(p), -1};
  });
  result.by_angle = Group(pixels_, options_, [&](const MaterialPixel& p) {
    return std::pair{-1, angle_bin(p)};
  });
  result.by_depth_and_angle = Group(pixels_, options_, [&](const MaterialPixel& p) {
    return std::pair{depth_bin(p), angle_bin(p)};
  });
  return result;
}

Summary SummariseDepthErrors(std::vector<float> errors_mm) {
  std::erase_if(errors_mm, [](float e) { return !std::isfinite(e); });
  return Summarise(errors_mm);
}

}  // namespace tofnav
