// SPDX-License-Identifier: BSD-3-Clause
// The coarse alignment search: anchored placements, their scores, and the grid refinement.
#include "tofnav/registration/coarse_search.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <optional>

#include "tofnav/core/dense_solvers.hpp"
#include "tofnav/core/parallel_for.hpp"
#include "tofnav/registration/point_to_plane.hpp"
#include "tofnav/registration/sampling.hpp"

namespace tofnav {
namespace {

template <typename Nearest>
double Score(const Samples& samples, const SurfaceIndex& target, const Nearest& nearest,
             const Eigen::Matrix3d& r, const Eigen::Vector3d& t, double gate_mm,
             double plane_scale_mm, bool early) {
  // Plain scalars (even the matrix copied out): this runs for every sample of tens of thousands
  // of placements, unoptimised test builds included.
  double m[3][4];
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col) m[row][col] = r(row, col);
    m[row][3] = t(row);
  }
  const double gate_sq = gate_mm * gate_mm;
  double score = 0.0;
  int hits = 0;
  for (std::size_t i = 0; i < samples.points.size(); ++i) {
    if (early && static_cast<int>(i) == kEarlySamples && hits < kEarlyMinHits) break;
    const double* p = samples.points[i].data();
    double x[3];
    for (int row = 0; row < 3; ++row) {
      x[row] = m[row][0] * p[0] + m[row][1] * p[1] + m[row][2] * p[2] + m[row][3];
    }
    const std::optional<std::uint32_t> near = nearest(x);
    if (!near) continue;
    const double* q = target.points()[*near].data();
    const double* n = target.normals()[*near].data();
    const double d[3] = {x[0] - q[0], x[1] - q[1], x[2] - q[2]};
    if (d[0] * d[0] + d[1] * d[1] + d[2] * d[2] >= gate_sq) continue;
    const double* normal = samples.normals[i].data();  // (R a) . n = a . (R^T n)
    double agreement = 0.0;
    for (int k = 0; k < 3; ++k) {
      agreement += normal[k] * (m[0][k] * n[0] + m[1][k] * n[1] + m[2][k] * n[2]);
    }
    if (agreement < kMinNormalCos) continue;
    const double plane = (n[0] * d[0] + n[1] * d[1] + n[2] * d[2]) / plane_scale_mm;
    score += std::max(0.0, 1.0 - plane * plane);
    ++hits;
  }
  return score / static_cast<double>(std::max<std::size_t>(samples.points.size(), 1));
}

bool Distinct(const Rigid3d& a, const Rigid3d& b, const Eigen::Vector3d& source_point,
              const CoarseAlignOptions& options) {
  return (a * source_point - b * source_point).norm() > options.distinct_translation_mm ||
         RotationDistanceRad(a, b) > options.distinct_rotation_rad;
}

}  // namespace

Samples Subset(const SurfaceIndex& surface, const std::vector<std::uint32_t>& indices) {
  return {Gather(surface.points(), indices), Gather(surface.normals(), indices)};
}

Eigen::Vector3d SmoothedNormal(const SurfaceIndex& surface, const Eigen::Vector3d& point,
                               double radius_mm) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Neighbour& n : surface.WithinRadius(point, radius_mm))
    sum += surface.normals()[n.index];
  return sum.norm() > 1e-9 ? Eigen::Vector3d(sum.normalized()) : Eigen::Vector3d::Zero();
}

double ScoreOnGrid(const Samples& samples, const SurfaceIndex& coarse_target,
                   const NearestSampleGrid& grid, const Eigen::Matrix3d& r,
                   const Eigen::Vector3d& t, double gate_mm, bool early) {
  const auto lookup = [&](const double* x) { return grid.Lookup(x); };
  return Score(samples, coarse_target, lookup, r, t, gate_mm, gate_mm, early);
}

double ScoreOnIndex(const Samples& samples, const SurfaceIndex& target, const Rigid3d& pose,
                    double gate_mm, double plane_scale_mm) {
  const auto nearest = [&](const double* x) -> std::optional<std::uint32_t> {
    const std::optional<Neighbour> n = target.Nearest(Eigen::Vector3d(x[0], x[1], x[2]), gate_mm);
    return n ? std::optional<std::uint32_t>(n->index) : std::nullopt;
  };
  return Score(samples, target, nearest, pose.RotationMatrix(), pose.translation, gate_mm,
               plane_scale_mm, false);
}

std::vector<Candidate> BestDistinct(std::vector<Candidate> all, std::size_t count,
                                    const Eigen::Vector3d& source_point,
                                    const CoarseAlignOptions& options) {
  std::stable_sort(all.begin(), all.end(),
                   [](const Candidate& a, const Candidate& b) { return a.score > b.score; });
  std::vector<Candidate> kept;
  for (const Candidate& c : all) {
    if (kept.size() == count || c.score <= 0.0) break;
    const bool distinct = std::all_of(kept.begin(), kept.end(), [&](const Candidate& k) {
      return Distinct(k.target_from_source, c.target_from_source, source_point, options);
    });
    if (distinct) kept.push_back(c);
  }
  return kept;
}

Rigid3d RefineOnGrid(const Samples& samples, const SurfaceIndex& coarse_target,
                     const NearestSampleGrid& grid, double slack_mm, Rigid3d pose,
                     const CoarseAlignOptions& options) {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : samples.points) centroid += p;
  centroid /= static_cast<double>(samples.points.size());
  for (const double gate_mm : options.refine_gates_mm) {
    for (int iteration = 0; iteration < options.refine_iterations; ++iteration) {
      const Eigen::Matrix3d rotation = pose.RotationMatrix();
      const Eigen::Vector3d centre = pose * centroid;
      double r[3][4];  // plain scalars in the per-sample loop
      for (int row = 0; row < 3; ++row) {
        for (int col = 0; col < 3; ++col) r[row][col] = rotation(row, col);
        r[row][3] = pose.translation(row);
      }
      const double reach_sq = (gate_mm + slack_mm) * (gate_mm + slack_mm);
      PointToPlaneSums sums;
      for (std::size_t i = 0; i < samples.points.size(); ++i) {
        const double* p = samples.points[i].data();
        double x[3];
        for (int row = 0; row < 3; ++row) {
          x[row] = r[row][0] * p[0] + r[row][1] * p[1] + r[row][2] * p[2] + r[row][3];
        }
        const std::optional<std::uint32_t> near = grid.Lookup(x);
        if (!near) continue;
        const double* q = coarse_target.points()[*near].data();
        const double* n = coarse_target.normals()[*near].data();
        const double d[3] = {x[0] - q[0], x[1] - q[1], x[2] - q[2]};
        const double residual_mm = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
        const double* a = samples.normals[i].data();  // (R a) . n = a . (R^T n)
        double agreement = 0.0;
        for (int k = 0; k < 3; ++k)
          agreement += a[k] * (r[0][k] * n[0] + r[1][k] * n[1] + r[2][k] * n[2]);
        if (std::abs(residual_mm) >= gate_mm ||
            d[0] * d[0] + d[1] * d[1] + d[2] * d[2] > reach_sq || agreement < kMinNormalCos) {
          continue;
        }
        const double u = residual_mm / gate_mm;
        sums.Add(x, n, centre.data(), residual_mm, (1.0 - u * u) * (1.0 - u * u));  // Tukey
      }
      if (sums.count < kMinRefineMatches) return pose;
      Matrix6d hessian = sums.Hessian();
      hessian.diagonal().array() += 1e-6 * std::max(hessian.diagonal().maxCoeff(), 1e-12);
      const Vector6d delta = -SolveSymmetric(hessian, sums.Gradient());
      pose = UpdateOnLeft(delta, centre, pose);
      if (delta.head<3>().norm() < 1e-4 && delta.tail<3>().norm() < 1e-2) break;
    }
  }
  return pose;
}

Placements::Placements(const SurfaceIndex& coarse_target, const SurfaceIndex& target,
                       const Eigen::Vector3d& anchor_in_source,
                       const Eigen::Vector3d& normal_in_source, const CoarseAlignOptions& options)
    : anchor_in_source_(anchor_in_source), rolls_(static_cast<std::size_t>(options.roll_steps)) {
  for (const std::uint32_t i : VoxelSubsample(target.points(), options.anchor_spacing_mm)) {
    const Eigen::Vector3d normal =
        SmoothedNormal(coarse_target, target.points()[i], options.normal_radius_mm);
    if (normal.isZero()) continue;
    anchors_.push_back(target.points()[i]);
    normals_.push_back(normal);
    tilts_.push_back(RotationBetween(normal_in_source, normal));
  }
}
Rigid3d Placements::Pose(std::size_t i) const {
  const std::size_t a = i / rolls_;
  const double roll_rad =
      2.0 * std::numbers::pi * static_cast<double>(i % rolls_) / static_cast<double>(rolls_);
  const Eigen::Quaterniond rotation = Eigen::AngleAxisd(roll_rad, normals_[a]) * tilts_[a];
  return {rotation, anchors_[a] - rotation * anchor_in_source_};
}

std::vector<double> Placements::Scores(const Samples& scoring, const SurfaceIndex& coarse_target,
                                       const NearestSampleGrid& grid, double gate_mm) const {
  std::vector<double> scores(size(), 0.0);
  ParallelFor(0, static_cast<std::int64_t>(anchors_.size()), [&](std::int64_t a) {
    const auto anchor = static_cast<std::size_t>(a);
    const Eigen::Matrix3d tilt = tilts_[anchor].toRotationMatrix();
    const Eigen::Vector3d& n = normals_[anchor];
    for (std::size_t k = 0; k < rolls_; ++k) {
      // Rodrigues: roll about n, then tilt (the same rotation as Pose()).
      const double angle =
          2.0 * std::numbers::pi * static_cast<double>(k) / static_cast<double>(rolls_);
      const double c = std::cos(angle), s = std::sin(angle), v = 1.0 - c;
      Eigen::Matrix3d roll;
      roll << c + v * n.x() * n.x(), v * n.x() * n.y() - s * n.z(), v * n.x() * n.z() + s * n.y(),
          v * n.y() * n.x() + s * n.z(), c + v * n.y() * n.y(), v * n.y() * n.z() - s * n.x(),
          v * n.z() * n.x() - s * n.y(), v * n.z() * n.y() + s * n.x(), c + v * n.z() * n.z();
      const Eigen::Matrix3d rotation = roll * tilt;
      scores[anchor * rolls_ + k] =
          ScoreOnGrid(scoring, coarse_target, grid, rotation,
                      anchors_[anchor] - rotation * anchor_in_source_, gate_mm, true);
    }
  });
  return scores;
}

std::vector<Candidate> BestPlacements(const Placements& placements,
                                      const std::vector<double>& scores, std::size_t count,
                                      const Eigen::Vector3d& source_point,
                                      const CoarseAlignOptions& options) {
  std::vector<std::size_t> order(scores.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return scores[a] > scores[b]; });
  std::vector<Candidate> kept;
  for (const std::size_t i : order) {
    if (kept.size() == count || scores[i] <= 0.0) break;
    const Rigid3d pose = placements.Pose(i);
    const bool distinct = std::all_of(kept.begin(), kept.end(), [&](const Candidate& k) {
      return Distinct(k.target_from_source, pose, source_point, options);
    });
    if (distinct) kept.push_back({pose, scores[i]});
  }
  return kept;
}

}  // namespace tofnav
