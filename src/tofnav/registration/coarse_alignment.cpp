// SPDX-License-Identifier: BSD-3-Clause
// Coarse alignment: exhaustive anchored placements (normal + roll), scored on a lookup grid,
// refined by a short point-to-plane ICP on the same grid, ranked at a fine gate.
#include "tofnav/registration/coarse_alignment.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "tofnav/core/parallel_for.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/registration/coarse_search.hpp"
#include "tofnav/registration/sampling.hpp"

namespace tofnav {
namespace {

constexpr double kFinalSampleMm = 3.0;      // source voxel before farthest-point sampling
constexpr double kGridCellFraction = 0.75;  // lookup grid cell, relative to target_spacing_mm
constexpr double kSpacingGate = 1.5;        // final gate at least this many target spacings

}  // namespace

void CoarseAlignOptions::Check() const {
  Require(target_spacing_mm > 0.0, "CoarseAlignOptions.target_spacing_mm must be > 0");
  Require(anchor_spacing_mm > 0.0, "CoarseAlignOptions.anchor_spacing_mm must be > 0");
  Require(normal_radius_mm > 0.0, "CoarseAlignOptions.normal_radius_mm must be > 0");
  Require(roll_steps >= 1, "CoarseAlignOptions.roll_steps must be >= 1");
  Require(score_samples >= kEarlySamples, "CoarseAlignOptions.score_samples must be >= 16");
  Require(score_gate_mm > 0.0, "CoarseAlignOptions.score_gate_mm must be > 0");
  Require(refine_candidates >= 1, "CoarseAlignOptions.refine_candidates must be >= 1");
  Require(refine_samples >= kMinRefineMatches, "CoarseAlignOptions.refine_samples must be >= 12");
  Require(!refine_gates_mm.empty(), "CoarseAlignOptions.refine_gates_mm is empty");
  for (const double gate : refine_gates_mm) {
    Require(gate > 0.0 && std::isfinite(gate), "CoarseAlignOptions.refine_gates_mm must be > 0");
  }
  Require(refine_iterations >= 1, "CoarseAlignOptions.refine_iterations must be >= 1");
  Require(result_candidates >= 1, "CoarseAlignOptions.result_candidates must be >= 1");
  Require(distinct_translation_mm >= 0.0 && distinct_rotation_rad >= 0.0,
          "CoarseAlignOptions.distinct_* must be >= 0");
  Require(final_gate_mm > 0.0, "CoarseAlignOptions.final_gate_mm must be > 0");
}

CoarseAlignResult AlignCoarse(const SurfaceIndex& source, const SurfaceIndex& target,
                              const CoarseAlignOptions& options) {
  options.Check();
  const Samples coarse = Subset(target, VoxelSubsample(target.points(), options.target_spacing_mm));
  const SurfaceIndex coarse_target(coarse.points, coarse.normals);

  // The source's central point: the one nearest the centroid (the middle of a face patch).
  const Eigen::Vector3d centroid =
      std::accumulate(source.points().begin(), source.points().end(), Eigen::Vector3d(0, 0, 0)) /
      static_cast<double>(source.size());
  const Eigen::Vector3d anchor = source.points()[source.KNearest(centroid, 1).front().index];
  const Eigen::Vector3d anchor_normal = SmoothedNormal(source, anchor, options.normal_radius_mm);
  Require(!anchor_normal.isZero(), "AlignCoarse: the source normals cancel at its centre");

  const Samples spread = Subset(source, VoxelSubsample(source.points(), kFinalSampleMm));
  const std::vector<std::uint32_t> order = FarthestPointSample(
      spread.points,
      static_cast<std::size_t>(std::max(options.score_samples, options.refine_samples)));
  const auto take = [&](std::size_t n) {
    const std::vector<std::uint32_t> first(
        order.begin(), order.begin() + static_cast<std::ptrdiff_t>(std::min(n, order.size())));
    return Samples{Gather(spread.points, first), Gather(spread.normals, first)};
  };
  const Samples scoring = take(static_cast<std::size_t>(options.score_samples));
  const Samples refining = take(static_cast<std::size_t>(options.refine_samples));

  const double cell_mm = kGridCellFraction * options.target_spacing_mm;
  const NearestSampleGrid grid(
      coarse.points, cell_mm,
      std::max(options.score_gate_mm,
               *std::max_element(options.refine_gates_mm.begin(), options.refine_gates_mm.end())));
  const Placements placements(coarse_target, target, anchor, anchor_normal, options);
  const std::vector<double> scores =
      placements.Scores(scoring, coarse_target, grid, options.score_gate_mm);
  std::vector<Candidate> refined = BestPlacements(
      placements, scores, static_cast<std::size_t>(options.refine_candidates), anchor, options);
  const double slack_mm = std::sqrt(3.0) * cell_mm;  // a grid lookup is off by up to a diagonal
  // A point on the surface can lie about one spacing from the nearest target sample.
  const double final_gate_mm = std::max(options.final_gate_mm, kSpacingGate * target.spacing_mm());
  ParallelFor(0, static_cast<std::int64_t>(refined.size()), [&](std::int64_t i) {
    Candidate& c = refined[static_cast<std::size_t>(i)];
    c.target_from_source =
        RefineOnGrid(refining, coarse_target, grid, slack_mm, c.target_from_source, options);
    c.score =
        ScoreOnIndex(refining, target, c.target_from_source, final_gate_mm, options.final_gate_mm);
  });

  CoarseAlignResult result;
  result.hypotheses = static_cast<int>(placements.size());
  for (const Candidate& c : BestDistinct(
           refined, static_cast<std::size_t>(options.result_candidates), anchor, options)) {
    result.candidates.push_back({c.target_from_source, c.score});
  }
  return result;
}

}  // namespace tofnav
