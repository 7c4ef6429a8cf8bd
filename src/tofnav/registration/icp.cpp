// SPDX-License-Identifier: BSD-3-Clause
// Robust point-to-plane ICP: gated correspondences, IRLS weights, Gauss-Newton on se(3).
#include "tofnav/registration/icp.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <utility>
#include <vector>

#include "tofnav/core/dense_solvers.hpp"
#include "tofnav/core/parallel_for.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/registration/point_to_plane.hpp"
#include "tofnav/registration/sampling.hpp"

namespace tofnav {
namespace {

constexpr std::size_t kChunk = 1024;      // points per task and per partial sum
constexpr int kNearestSet = 4;            // target points kept per query: a point between skin
                                          // samples keeps its answer while it moves (measured on
                                          // the demo's identification: docs/registration.md 5)
constexpr double kOrderCellMm = 4.0;      // Morton cell of the query order
constexpr double kMadToSigma = 1.4826;    // median |r| of a unit Gaussian is 1 / 1.4826
constexpr double kHuberK = 1.345;         // 95 % efficiency under Gaussian noise
constexpr double kTukeyC = 4.685;         // ditto
constexpr std::size_t kCycle = 12;        // longest correspondence cycle recognised as converged
constexpr double kSettledFactor = 100.0;  // a level out of iterations counts as converged when
                                          // its last kCycle poses lie within this many
                                          // convergence thresholds (a long cycle in the noise)
constexpr double kUnconstrained = 1e-8;   // relative eigenvalue of J^T J treated as zero

/// One source point after the current transform, matched (or not) to the target.
struct Match {
  Eigen::Vector3d point_in_target = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // the target's
  double residual_mm = 0.0;                          // n . (x - q), Chen & Medioni 1992
  bool valid = false;
  // The last KD-tree query: where the point was, its nearest target points (closest first) and
  // a distance that every other target point lies beyond. Until the point has moved so far that
  // one of those could come nearer than the nearest of the set, the nearest target point is the
  // set's nearest, and the query is skipped: the result is exactly that of a new query.
  Eigen::Vector3d queried_at = Eigen::Vector3d::Zero();
  std::optional<std::uint32_t> nearest;
  std::array<std::uint32_t, kNearestSet> set{};
  int set_count = 0;
  double others_from_mm = -1.0;  // negative: no query yet
};

std::size_t ChunkCount(std::size_t n) { return (n + kChunk - 1) / kChunk; }

/// The point's nearest target point now that it lies at `point_in_target`, from its last query,
/// when that provably holds: one set point nearer than every other set point and than
/// others_from_mm minus the distance moved (every point outside the set lies at least that far).
/// The margin keeps the proof safe from the last bits of the distances.
std::optional<std::uint32_t> NearestFromSet(const Match& m, const Eigen::Vector3d& point_in_target,
                                            const Eigen::Vector3d* target) {
  constexpr double kMarginMm = 1e-9;
  if (m.set_count == 0) return std::nullopt;
  const double limit_mm = m.others_from_mm - (point_in_target - m.queried_at).norm() - kMarginMm;
  if (!(limit_mm > 0.0)) return std::nullopt;
  double best_sq = std::numeric_limits<double>::infinity(), second_sq = best_sq;
  int best = 0;
  for (int k = 0; k < m.set_count; ++k) {
    const double d_sq =
        (target[m.set[static_cast<std::size_t>(k)]] - point_in_target).squaredNorm();
    if (d_sq < best_sq) {
      second_sq = best_sq;
      best_sq = d_sq;
      best = k;
    } else if (d_sq < second_sq) {
      second_sq = d_sq;
    }
  }
  const double best_mm = std::sqrt(best_sq);
  if (best_mm < limit_mm && best_mm + kMarginMm < std::sqrt(second_sq)) {
    return m.set[static_cast<std::size_t>(best)];
  }
  return std::nullopt;
}

/// A new query at the point's place: its nearest target point within `max_distance_mm` and the
/// set kept for the next calls. A tie for the nearest (duplicated target points) keeps no set:
/// which of them a new query names is the search's business, so the next call asks it again.
void Query(Match& m, const SurfaceIndex& target, double max_distance_mm) {
  const SurfaceIndex::NearestSet near =
      target.NearestK(m.point_in_target, kNearestSet, max_distance_mm);
  m.queried_at = m.point_in_target;
  m.nearest = near.count > 0 ? std::optional<std::uint32_t>(near.nearest[0].index) : std::nullopt;
  const bool tie =
      near.count > 1 && near.nearest[1].distance_sq_mm2 == near.nearest[0].distance_sq_mm2;
  m.set_count = tie ? 0 : near.count;
  for (int k = 0; k < m.set_count; ++k) {
    m.set[static_cast<std::size_t>(k)] = near.nearest[static_cast<std::size_t>(k)].index;
  }
  m.others_from_mm = near.others_from_mm;
}

/// Calls body(first, last) per chunk in parallel and adds the per-chunk sums in chunk order, so
/// the floating-point result does not depend on the thread count.
template <typename Body>
PointToPlaneSums ReduceChunks(std::size_t n, const Body& body) {
  std::vector<PointToPlaneSums> partial(ChunkCount(n));
  ParallelFor(0, static_cast<std::int64_t>(partial.size()), [&](std::int64_t c) {
    const std::size_t first = static_cast<std::size_t>(c) * kChunk;
    partial[static_cast<std::size_t>(c)] = body(first, std::min(n, first + kChunk));
  });
  PointToPlaneSums total;
  for (const PointToPlaneSums& s : partial) total.Add(s);
  return total;
}

/// Moves every source point into the target and finds its gated closest target point (exactly:
/// a cached KD-tree answer is reused only while it provably cannot change).
void Associate(const Points3d& points, const Points3d& normals, const SurfaceIndex& target,
               const Rigid3d& target_from_source, double max_distance_mm, double min_cos,
               std::vector<Match>& matches) {
  matches.resize(points.size());
  // Plain scalars (the matrix copied out) in the per-point loop: it dominates unoptimised test
  // builds too.
  const Eigen::Matrix3d rotation = target_from_source.RotationMatrix();
  double r[3][3], t[3];
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col) r[row][col] = rotation(row, col);
    t[row] = target_from_source.translation(row);
  }
  ParallelFor(0, static_cast<std::int64_t>(ChunkCount(points.size())), [&](std::int64_t c) {
    const std::size_t first = static_cast<std::size_t>(c) * kChunk;
    const std::size_t last = std::min(points.size(), first + kChunk);
    for (std::size_t i = first; i < last; ++i) {
      Match& m = matches[i];
      const double* p = points[i].data();
      m.point_in_target = {r[0][0] * p[0] + r[0][1] * p[1] + r[0][2] * p[2] + t[0],
                           r[1][0] * p[0] + r[1][1] * p[1] + r[1][2] * p[2] + t[1],
                           r[2][0] * p[0] + r[2][1] * p[1] + r[2][2] * p[2] + t[2]};
      m.valid = false;
      if (const std::optional<std::uint32_t> known =
              NearestFromSet(m, m.point_in_target, target.points().data())) {
        m.nearest = known;
      } else {
        Query(m, target, max_distance_mm);
      }
      if (!m.nearest) continue;
      const double* q = target.points()[*m.nearest].data();
      const double* x = m.point_in_target.data();
      const double d[3] = {x[0] - q[0], x[1] - q[1], x[2] - q[2]};
      if (d[0] * d[0] + d[1] * d[1] + d[2] * d[2] >= max_distance_mm * max_distance_mm) continue;
      const double* n = target.normals()[*m.nearest].data();
      if (!normals.empty()) {
        const double* s = normals[i].data();  // (R s) . n = s . (R^T n)
        double agreement = 0.0;
        for (int k = 0; k < 3; ++k) {
          agreement += s[k] * (r[0][k] * n[0] + r[1][k] * n[1] + r[2][k] * n[2]);
        }
        if (agreement < min_cos) continue;
      }
      m.normal = {n[0], n[1], n[2]};
      m.residual_mm = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
      m.valid = true;
    }
  });
}

/// 1.4826 * median |residual| over the valid matches (0 when there are none).
double MadSigma(const std::vector<Match>& matches) {
  std::vector<double> magnitudes;
  magnitudes.reserve(matches.size());
  for (const Match& m : matches) {
    if (m.valid) magnitudes.push_back(std::abs(m.residual_mm));
  }
  if (magnitudes.empty()) return 0.0;
  const auto middle = magnitudes.begin() + static_cast<std::ptrdiff_t>(magnitudes.size() / 2);
  std::nth_element(magnitudes.begin(), middle, magnitudes.end());
  return kMadToSigma * *middle;
}

/// IRLS weight of a residual (Huber 1964; Beaton & Tukey 1974).
double RobustWeight(RobustLoss loss, double residual_mm, double scale_mm) {
  const double u = std::abs(residual_mm) / scale_mm;
  switch (loss) {
    case RobustLoss::kSquared:
      return 1.0;
    case RobustLoss::kHuber:
      return u <= kHuberK ? 1.0 : kHuberK / u;
    case RobustLoss::kTukey: {
      if (u >= kTukeyC) return 0.0;
      const double a = 1.0 - (u / kTukeyC) * (u / kTukeyC);
      return a * a;
    }
  }
  return 1.0;
}

/// Weighted normal equations of the point-to-plane residual about `centre`:
/// J = [((x - c) x n)^T, n^T], H = sum w J^T J, g = sum w J^T r.
PointToPlaneSums NormalEquations(const std::vector<Match>& matches, const Eigen::Vector3d& centre,
                                 RobustLoss loss, double scale_mm) {
  return ReduceChunks(matches.size(), [&](std::size_t first, std::size_t last) {
    PointToPlaneSums s;
    for (std::size_t i = first; i < last; ++i) {
      const Match& m = matches[i];
      if (!m.valid) continue;
      s.Add(m.point_in_target.data(), m.normal.data(), centre.data(), m.residual_mm,
            RobustWeight(loss, m.residual_mm, scale_mm));
    }
    return s;
  });
}

/// Solves H delta = -g in the subspace the surface constrains: directions whose eigenvalue is
/// below kUnconstrained of the largest (a sphere's turn about its centre) get no step, instead of
/// an arbitrary one driven by round-off.
Vector6d SolveStep(const PointToPlaneSums& sums) {
  const auto solver = DecomposeSymmetric(sums.Hessian());
  const Vector6d& values = solver.values;
  Vector6d inverse = Vector6d::Zero();
  for (int i = 0; i < 6; ++i) {
    if (values(i) > kUnconstrained * values(5)) inverse(i) = 1.0 / values(i);
  }
  return -(solver.vectors * inverse.asDiagonal() * solver.vectors.transpose() * sums.Gradient());
}

/// The final statistics at the finest gate: inliers, RMSE, sigma, information about the centroid.
void FinalStatistics(const std::vector<Match>& matches, std::size_t source_count,
                     const IcpOptions& options, IcpResult& result) {
  result.inlier_indices.clear();
  double sum_sq = 0.0;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < matches.size(); ++i) {
    if (!matches[i].valid) continue;
    result.inlier_indices.push_back(static_cast<std::uint32_t>(i));
    sum_sq += matches[i].residual_mm * matches[i].residual_mm;
    sum += matches[i].point_in_target;
  }
  const auto count = static_cast<int>(result.inlier_indices.size());
  result.correspondences = count;
  result.inlier_fraction =
      source_count == 0 ? 0.0 : static_cast<double>(count) / static_cast<double>(source_count);
  if (count == 0) return;
  result.rmse_mm = std::sqrt(sum_sq / count);
  result.residual_sigma_mm = MadSigma(matches);
  result.centre_in_target = sum / count;
  result.information =
      NormalEquations(matches, result.centre_in_target, RobustLoss::kSquared, 1.0).Hessian();
  result.conditioning =
      ComputeConditioning(result.information, count, options.conditioning_radius_mm);
}

}  // namespace

struct IcpNeighbourCache::Impl {
  const Eigen::Vector3d* target_points = nullptr;  // the target the answers belong to
  std::size_t target_size = 0;
  std::vector<Match> matches;  // the caller's order
};

IcpNeighbourCache::IcpNeighbourCache() : impl_(std::make_unique<Impl>()) {}
IcpNeighbourCache::~IcpNeighbourCache() = default;
IcpNeighbourCache::IcpNeighbourCache(IcpNeighbourCache&&) noexcept = default;
IcpNeighbourCache& IcpNeighbourCache::operator=(IcpNeighbourCache&&) noexcept = default;

std::optional<std::uint32_t> IcpNeighbourCache::KnownNearest(
    std::size_t index, const Eigen::Vector3d& point_in_target) const {
  if (!impl_ || index >= impl_->matches.size()) return std::nullopt;
  const Match& m = impl_->matches[index];
  return NearestFromSet(m, point_in_target, impl_->target_points);
}

void IcpOptions::Check() const {
  Require(!max_distance_schedule_mm.empty(), "IcpOptions.max_distance_schedule_mm is empty");
  for (const double gate : max_distance_schedule_mm) {
    Require(gate > 0.0 && std::isfinite(gate), "IcpOptions.max_distance_schedule_mm must be > 0");
  }
  Require(max_normal_angle_rad > 0.0 && max_normal_angle_rad <= std::numbers::pi,
          "IcpOptions.max_normal_angle_rad must lie in (0, pi]");
  Require(min_robust_scale_mm > 0.0, "IcpOptions.min_robust_scale_mm must be > 0");
  Require(max_iterations_per_level >= 1, "IcpOptions.max_iterations_per_level must be >= 1");
  Require(convergence_rotation_rad >= 0.0, "IcpOptions.convergence_rotation_rad must be >= 0");
  Require(convergence_translation_mm >= 0.0, "IcpOptions.convergence_translation_mm must be >= 0");
  Require(min_correspondences >= 6, "IcpOptions.min_correspondences must be >= 6");
  Require(conditioning_radius_mm > 0.0, "IcpOptions.conditioning_radius_mm must be > 0");
}

IcpResult AlignPointToPlane(const Points3d& source_points, const Points3d& source_normals,
                            const SurfaceIndex& target, const Rigid3d& target_from_source_guess,
                            const IcpOptions& options, IcpNeighbourCache* cache) {
  options.Check();
  Require(source_normals.empty() || source_normals.size() == source_points.size(),
          "AlignPointToPlane: one source normal per point, or none");
  IcpResult result;
  result.target_from_source = target_from_source_guess;
  const double min_cos = std::cos(options.max_normal_angle_rad);
  Eigen::Vector3d source_centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : source_points) source_centroid += p;
  if (!source_points.empty()) source_centroid /= static_cast<double>(source_points.size());
  // Work in a spatially coherent order: consecutive queries walk the same KD-tree branches.
  const std::vector<std::uint32_t> order = SpatialOrder(source_points, kOrderCellMm);
  const Points3d points = Gather(source_points, order);
  const Points3d normals = source_normals.empty() ? Points3d{} : Gather(source_normals, order);

  std::vector<Match> matches;
  IcpNeighbourCache::Impl* kept = cache != nullptr ? &cache->impl() : nullptr;
  if (kept != nullptr && kept->target_points == target.points().data() &&
      kept->target_size == target.points().size() && kept->matches.size() == source_points.size()) {
    matches.resize(order.size());  // each answer is checked before it is reused
    for (std::size_t i = 0; i < order.size(); ++i) matches[i] = kept->matches[order[i]];
  }
  bool level_converged = false;
  bool enough = true;
  const auto levels = static_cast<int>(options.max_distance_schedule_mm.size());
  for (int level = 0; level < levels && enough; ++level) {
    const double gate_mm = std::max(
        options.max_distance_schedule_mm[static_cast<std::size_t>(level)], target.spacing_mm());
    level_converged = false;
    result.out_of_iterations = false;  // the verdict weighs the last level's settling only
    result.unsettled_rotation_rad = 0.0;
    result.unsettled_translation_mm = 0.0;
    std::vector<Rigid3d> recent = {result.target_from_source};  // the last kCycle poses
    for (int iteration = 0; iteration < options.max_iterations_per_level; ++iteration) {
      Associate(points, normals, target, result.target_from_source, gate_mm, min_cos, matches);
      const double scale_mm = std::max(MadSigma(matches), options.min_robust_scale_mm);
      // Linearise about the moved source centroid: better conditioned than the target origin.
      const Eigen::Vector3d centre = result.target_from_source * source_centroid;
      const PointToPlaneSums sums = NormalEquations(matches, centre, options.loss, scale_mm);
      if (sums.count < options.min_correspondences) {
        enough = false;
        break;
      }
      const Vector6d delta = SolveStep(sums);
      result.target_from_source = UpdateOnLeft(delta, centre, result.target_from_source);
      ++result.iterations;
      IcpIterationStats stats{.level = level,
                              .max_distance_mm = gate_mm,
                              .correspondences = sums.count,
                              .robust_scale_mm = scale_mm,
                              .step_rotation_rad = delta.head<3>().norm(),
                              .step_translation_mm = delta.tail<3>().norm()};
      double sum_sq = 0.0;
      for (const Match& m : matches) sum_sq += m.valid ? m.residual_mm * m.residual_mm : 0.0;
      stats.rmse_mm = std::sqrt(sum_sq / sums.count);
      result.history.push_back(stats);
      // Converged when the step is tiny, or when the pose returns to one of the last few: a
      // point flipping between nearest neighbours makes a short cycle that never settles.
      // How far the pose lies from another: rotation, and translation of the source centroid.
      const auto moved = [&](const Rigid3d& other) {
        return std::pair{
            RotationDistanceRad(result.target_from_source, other),
            (result.target_from_source * source_centroid - other * source_centroid).norm()};
      };
      const auto within = [&](double factor) {
        return [&, factor](const Rigid3d& other) {
          const auto [rotation_rad, translation_mm] = moved(other);
          return rotation_rad <= factor * options.convergence_rotation_rad &&
                 translation_mm <= factor * options.convergence_translation_mm;
        };
      };
      if (std::any_of(recent.begin(), recent.end(), within(1.0))) {
        level_converged = true;
        break;
      }
      if (iteration + 1 == options.max_iterations_per_level && recent.size() == kCycle &&
          std::all_of(recent.begin(), recent.end(), within(kSettledFactor))) {
        level_converged = true;
      }
      if (iteration + 1 == options.max_iterations_per_level && !level_converged) {
        result.out_of_iterations = true;
        for (const Rigid3d& other : recent) {
          const auto [rotation_rad, translation_mm] = moved(other);
          result.unsettled_rotation_rad = std::max(result.unsettled_rotation_rad, rotation_rad);
          result.unsettled_translation_mm =
              std::max(result.unsettled_translation_mm, translation_mm);
        }
      }
      if (recent.size() == kCycle) recent.erase(recent.begin());
      recent.push_back(result.target_from_source);
    }
  }
  Associate(points, normals, target, result.target_from_source,
            std::max(options.max_distance_schedule_mm.back(), target.spacing_mm()), min_cos,
            matches);
  FinalStatistics(matches, source_points.size(), options, result);
  if (kept != nullptr) {
    kept->target_points = target.points().data();
    kept->target_size = target.points().size();
    kept->matches.resize(matches.size());
    for (std::size_t i = 0; i < matches.size(); ++i) kept->matches[order[i]] = matches[i];
  }
  for (std::uint32_t& i : result.inlier_indices) i = order[i];  // back to the caller's indices
  std::sort(result.inlier_indices.begin(), result.inlier_indices.end());
  result.converged =
      enough && level_converged && result.correspondences >= options.min_correspondences;
  return result;
}

}  // namespace tofnav
