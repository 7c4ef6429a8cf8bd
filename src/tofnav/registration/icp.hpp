// SPDX-License-Identifier: BSD-3-Clause
// Robust point-to-plane ICP (Chen & Medioni 1992) of source points to a SurfaceIndex.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "tofnav/core/point_cloud.hpp"
#include "tofnav/core/rigid3d.hpp"
#include "tofnav/registration/pose_conditioning.hpp"
#include "tofnav/registration/surface_index.hpp"

namespace tofnav {

enum class RobustLoss {
  kSquared,  // plain least squares inside the gate
  kHuber,    // quadratic up to 1.345 scale, then linear
  kTukey,    // Tukey biweight, zero weight beyond 4.685 scale
};

struct IcpOptions {
  /// Correspondence distance gate per level, coarse to fine [mm]; each level runs to convergence.
  /// A gate below the target's spacing_mm() is raised to it (a point on the surface can lie that
  /// far from the nearest target sample).
  std::vector<double> max_distance_schedule_mm = {10.0, 5.0, 2.5};
  /// Correspondences whose normals (source rotated into the target) differ by more are dropped.
  /// Ignored when the source has no normals. Normals must be oriented alike (e.g. outwards).
  double max_normal_angle_rad = 1.0472;  // 60 deg: hair, back faces, ears
  RobustLoss loss = RobustLoss::kHuber;
  /// The robust scale is 1.4826 * median |residual| (MAD), but never below this [mm].
  double min_robust_scale_mm = 0.05;
  int max_iterations_per_level = 30;
  double convergence_rotation_rad = 1e-6;  // a level ends when a step is below both
  double convergence_translation_mm = 1e-4;
  int min_correspondences = 12;           // fewer and the alignment gives up (converged = false)
  double conditioning_radius_mm = 100.0;  // rotation scaled to mm at about a head's radius
  void Check() const;                     // throws std::invalid_argument naming the field
};

struct IcpIterationStats {
  int level = 0;
  double max_distance_mm = 0.0;
  int correspondences = 0;
  double rmse_mm = 0.0;          // RMS point-to-plane residual of the correspondences
  double robust_scale_mm = 0.0;  // 1.4826 * MAD (floored)
  double step_rotation_rad = 0.0;
  double step_translation_mm = 0.0;
};

struct IcpResult {
  Rigid3d target_from_source;
  bool converged = false;  // the last level converged, with enough correspondences throughout
  int iterations = 0;      // over all levels
  /// A level ran out of iterations (with enough correspondences): the pose still moved, by at
  /// most these over its last 12 iterations (rotation; translation of the source centroid).
  /// 0 when every level ended on a small step or a short cycle.
  bool out_of_iterations = false;
  double unsettled_rotation_rad = 0.0;
  double unsettled_translation_mm = 0.0;
  /// At the final transform and the finest gate:
  int correspondences = 0;
  double inlier_fraction = 0.0;    // correspondences / source points
  double rmse_mm = 0.0;            // RMS point-to-plane residual of the correspondences
  double residual_sigma_mm = 0.0;  // robust: 1.4826 * median |residual| (no floor)
  /// Gauss-Newton information J^T J (unit weights, final correspondences) of the left update
  /// x -> exp(omega) (x - centre) + centre + v, delta = (omega [rad], v [mm]), with the centre the
  /// centroid of the matched source points in the target frame.
  Matrix6d information = Matrix6d::Zero();
  Eigen::Vector3d centre_in_target = Eigen::Vector3d::Zero();
  PoseConditioning conditioning;              // of `information`, at options.conditioning_radius_mm
  std::vector<std::uint32_t> inlier_indices;  // source points of the final correspondences
  std::vector<IcpIterationStats> history;
};

/// The nearest-neighbour answers of one ICP's source points, kept for the next ICP on the same
/// target with as many source points (which may have moved: an identification's cost evaluations
/// align the same samples under slightly different depth models). An answer is reused only while
/// it provably cannot change: each query keeps the point's few nearest target points and a
/// distance every other target point lies beyond; while one kept point stays nearer than the
/// others and than that distance less how far the point moved, it is the nearest, so every result
/// is exactly that without the cache (docs/registration.md 5). One cache per sequence of calls: not
/// for concurrent use.
class IcpNeighbourCache {
 public:
  IcpNeighbourCache();
  ~IcpNeighbourCache();
  IcpNeighbourCache(IcpNeighbourCache&&) noexcept;
  IcpNeighbourCache& operator=(IcpNeighbourCache&&) noexcept;
  IcpNeighbourCache(const IcpNeighbourCache&) = delete;
  IcpNeighbourCache& operator=(const IcpNeighbourCache&) = delete;

  /// The nearest target point of the last call's source point `index` (the caller's order) when
  /// it lies at `point_in_target`, if the cached answer provably still holds; nothing otherwise.
  std::optional<std::uint32_t> KnownNearest(std::size_t index,
                                            const Eigen::Vector3d& point_in_target) const;

  struct Impl;  // defined in icp.cpp: opaque elsewhere
  Impl& impl() { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
};

/// Point-to-plane ICP (Chen & Medioni 1992) with a coarse-to-fine distance gate, a normal-angle
/// gate and an IRLS robust loss; Gauss-Newton on se(3) with 6x6 normal equations. Parallel, with
/// per-chunk sums added in a fixed order, so the result is the same for any thread count.
/// @param source_normals  unit normals of the source points (same frame), or empty
/// @param cache  nearest-neighbour answers from the previous call on this target, or null
IcpResult AlignPointToPlane(const Points3d& source_points, const Points3d& source_normals,
                            const SurfaceIndex& target, const Rigid3d& target_from_source_guess,
                            const IcpOptions& options = {}, IcpNeighbourCache* cache = nullptr);

}  // namespace tofnav
