// SPDX-License-Identifier: BSD-3-Clause
// Candidate tool-to-scene marker correspondences by pairwise distances (docs/tracking.md 7.2, 9.3).
#pragma once

#include <Eigen/Core>
#include <span>
#include <vector>

#include "tofnav/core/rigid_fit.hpp"
#include "tofnav/tracking/tool_geometry.hpp"

namespace tofnav {

/// Distance tolerance growing with range: clamp(base_mm + per_range * mean range, min, max).
struct MatchTolerance {
  double base_mm = 1.5;
  double per_range = 0.004;  // dimensionless: mm of tolerance per mm of range
  double min_mm = 1.5;
  double max_mm = 6.0;
  double AtMm(double range_mm) const;
  void Check() const;  // throws std::invalid_argument naming the bad field
};

struct CandidateSearchOptions {
  MatchTolerance tolerance;
  double max_fre_mm = 1.0;  // candidates with a larger RMS fit error are dropped
  int max_nodes = 200000;   // search budget; when spent the result says `truncated`
  void Check() const;
};

/// One candidate: which scene point each tool marker took (-1 = unseen) and the fitted pose.
struct ToolCandidate {
  std::vector<int> scene_index;  // per tool marker
  int visible = 0;               // markers with a scene point
  RigidFitResult fit;            // target = ahat, source = tool
};

struct CandidateSearchResult {
  std::vector<ToolCandidate> candidates;  // none is a sub-assignment of another
  bool truncated = false;                 // the node budget ran out: the list may be incomplete
};

/// Interpretation-tree search: every assignment of at least `min_visible` tool markers to
/// distinct scene points whose pairwise distances all agree within the range-scaled tolerance,
/// fitted by Kabsch and kept when FRE <= max_fre_mm. Sub-assignments of a kept candidate are
/// dropped (they are the same physical match with markers left out).
CandidateSearchResult FindToolCandidates(std::span<const Eigen::Vector3d> scene_in_ahat,
                                         const ToolGeometry& tool, int min_visible,
                                         const CandidateSearchOptions& options = {});

}  // namespace tofnav
