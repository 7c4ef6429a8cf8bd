// SPDX-License-Identifier: BSD-3-Clause
// Automatic coarse alignment of a partial surface to a complete one: no hand placement, any
// starting orientation.
#pragma once

#include <vector>

#include "tofnav/core/rigid3d.hpp"
#include "tofnav/registration/surface_index.hpp"

namespace tofnav {

/// The search places the source's central point, with its smoothed normal, on every anchor of the
/// target (a grid over the whole surface) at every roll about the normal; scores each placement
/// by how many source samples land on the target with matching normals; refines the best distinct
/// placements by a short point-to-plane ICP on a lookup grid; and ranks them by their fit at a
/// fine gate. A smooth head fits roughly in many places, so the ranking is made only after the
/// refinement. Defaults suit a head (CT skin against a face patch).
/// Chosen over FPFH + RANSAC: skin is smooth, so local descriptors are weak and noise-sensitive,
/// while this search is deterministic, needs no initial pose (any orientation) and handles a
/// partial source (its anchor only has to lie somewhere on the target).
struct CoarseAlignOptions {
  double target_spacing_mm = 4.0;   // voxel subsampling of the target for the search
  double anchor_spacing_mm = 10.0;  // one anchor per voxel of this size over the target
  double normal_radius_mm = 15.0;   // normals averaged over this radius at the anchors
  int roll_steps = 16;              // placements about the anchor normal (22.5 deg apart)
  int score_samples = 48;           // source points, farthest-point sampled, per placement
  double score_gate_mm = 8.0;       // a sample counts when a target point lies this close
  int refine_candidates = 48;       // distinct best placements refined
  int refine_samples = 150;         // source points in the refinement
  std::vector<double> refine_gates_mm = {12.0, 6.0, 3.0};  // point-to-plane gate per level
  int refine_iterations = 6;                               // per level
  int result_candidates = 4;              // distinct refined poses returned, best first
  double distinct_translation_mm = 12.0;  // poses closer than both of these are one
  double distinct_rotation_rad = 0.35;
  /// The refined poses are ranked by their fit at this plane distance (the nearest-point gate is
  /// at least 1.5 target spacings, for coarsely sampled targets).
  double final_gate_mm = 2.0;
  void Check() const;  // throws std::invalid_argument naming the field
};

struct CoarseCandidate {
  Rigid3d target_from_source;
  /// Soft inlier fraction (0..1) of the refinement samples at final_gate_mm against the full
  /// target: 1 when every sample lies on the target with a matching normal.
  double score = 0.0;
};

struct CoarseAlignResult {
  std::vector<CoarseCandidate> candidates;  // distinct, best first; empty: no overlap anywhere
  int hypotheses = 0;                       // placements scored
  bool found() const { return !candidates.empty(); }
};

/// Coarse `target_from_source` candidates for a source surface overlapping part of the target.
/// Both indices need consistently oriented (outward) normals.
CoarseAlignResult AlignCoarse(const SurfaceIndex& source, const SurfaceIndex& target,
                              const CoarseAlignOptions& options = {});

}  // namespace tofnav
