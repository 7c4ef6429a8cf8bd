// SPDX-License-Identifier: BSD-3-Clause
// Internal to registration/: the pieces of the coarse alignment search (coarse_alignment.cpp).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "tofnav/core/point_cloud.hpp"
#include "tofnav/core/rigid3d.hpp"
#include "tofnav/registration/coarse_alignment.hpp"
#include "tofnav/registration/nearest_sample_grid.hpp"
#include "tofnav/registration/surface_index.hpp"

namespace tofnav {

inline constexpr double kMinNormalCos = 0.5;  // 60 deg: samples with worse agreement miss
inline constexpr int kEarlySamples = 16;      // a placement is dropped when fewer than
inline constexpr int kEarlyMinHits = 4;       // this many of its first samples land on the target
inline constexpr int kMinRefineMatches = 12;  // fewer and a refinement stops

/// A surface subset with normals, as plain vectors.
struct Samples {
  Points3d points;
  Points3d normals;
};
Samples Subset(const SurfaceIndex& surface, const std::vector<std::uint32_t>& indices);

/// Mean of the normals within `radius_mm` of `point`, normalised (zero when they cancel).
Eigen::Vector3d SmoothedNormal(const SurfaceIndex& surface, const Eigen::Vector3d& point,
                               double radius_mm);

struct Candidate {
  Rigid3d target_from_source;
  double score = 0.0;
};

/// Soft inlier score of samples under x -> r x + t: each sample whose nearest target point lies
/// within `gate_mm` with a compatible normal adds 1 - (plane distance / plane_scale_mm)^2 when
/// positive; divided by the sample count. On the grid the nearest point is approximate and, with
/// `early`, a placement gives up after kEarlySamples samples with fewer than kEarlyMinHits hits.
double ScoreOnGrid(const Samples& samples, const SurfaceIndex& coarse_target,
                   const NearestSampleGrid& grid, const Eigen::Matrix3d& r,
                   const Eigen::Vector3d& t, double gate_mm, bool early);
double ScoreOnIndex(const Samples& samples, const SurfaceIndex& target, const Rigid3d& pose,
                    double gate_mm, double plane_scale_mm);

/// A short point-to-plane ICP on the lookup grid (approximate nearest samples, which is enough
/// to pull a placement into the basin): Tukey weights with the gate as scale, per gate level.
/// @param slack_mm  how much farther than its true nearest a grid lookup can be
Rigid3d RefineOnGrid(const Samples& samples, const SurfaceIndex& coarse_target,
                     const NearestSampleGrid& grid, double slack_mm, Rigid3d pose,
                     const CoarseAlignOptions& options);

/// Every anchored placement: the source anchor on a target anchor, normals aligned, turned by a
/// roll about the normal. Scores are computed for all, poses only for the few that are kept.
class Placements {
 public:
  Placements(const SurfaceIndex& coarse_target, const SurfaceIndex& target,
             const Eigen::Vector3d& anchor_in_source, const Eigen::Vector3d& normal_in_source,
             const CoarseAlignOptions& options);
  std::size_t size() const { return anchors_.size() * rolls_; }
  /// Pose of placement `i` (anchor i / rolls, roll i % rolls).
  Rigid3d Pose(std::size_t i) const;
  /// Score of every placement on `scoring` samples against the lookup grid (parallel).
  std::vector<double> Scores(const Samples& scoring, const SurfaceIndex& coarse_target,
                             const NearestSampleGrid& grid, double gate_mm) const;

 private:
  Eigen::Vector3d anchor_in_source_;
  std::size_t rolls_;
  Points3d anchors_, normals_;
  std::vector<Eigen::Quaterniond> tilts_;
};

/// The `count` best-scoring placements that are distinct from each other.
std::vector<Candidate> BestPlacements(const Placements& placements,
                                      const std::vector<double>& scores, std::size_t count,
                                      const Eigen::Vector3d& source_point,
                                      const CoarseAlignOptions& options);
/// Best-first, skipping candidates that repeat an accepted one (non-maximum suppression).
std::vector<Candidate> BestDistinct(std::vector<Candidate> all, std::size_t count,
                                    const Eigen::Vector3d& source_point,
                                    const CoarseAlignOptions& options);

}  // namespace tofnav
