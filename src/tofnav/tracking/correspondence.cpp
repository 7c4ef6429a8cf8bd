// SPDX-License-Identifier: BSD-3-Clause
// Interpretation-tree matching of a tool's inter-marker distances to scene points.
#include "tofnav/tracking/correspondence.hpp"

#include <algorithm>
#include <cmath>

#include "tofnav/core/require.hpp"

namespace tofnav {
namespace {

class Search {
 public:
  Search(std::span<const Eigen::Vector3d> scene, const ToolGeometry& tool, int min_visible,
         const CandidateSearchOptions& options)
      : scene_(scene),
        tool_(tool),
        min_visible_(min_visible),
        options_(options),
        n_(scene.size()),
        m_(tool.markers_in_tool.size()),
        used_(n_, false),
        assignment_(m_, -1) {
    scene_distance_.resize(n_ * n_);
    tolerance_.resize(n_ * n_);
    for (std::size_t i = 0; i < n_; ++i) {
      for (std::size_t j = 0; j < n_; ++j) {
        scene_distance_[i * n_ + j] = (scene[i] - scene[j]).norm();
        tolerance_[i * n_ + j] = options.tolerance.AtMm(0.5 * (scene[i].norm() + scene[j].norm()));
      }
    }
    tool_distance_.resize(m_ * m_);
    for (std::size_t a = 0; a < m_; ++a) {
      for (std::size_t b = 0; b < m_; ++b) {
        tool_distance_[a * m_ + b] = (tool.markers_in_tool[a] - tool.markers_in_tool[b]).norm();
      }
    }
  }

  CandidateSearchResult Run() {
    Visit(0, 0);
    DropSubAssignments();
    return std::move(result_);
  }

 private:
  void Visit(std::size_t k, int unseen) {
    if (++nodes_ > options_.max_nodes) {
      result_.truncated = true;
      return;
    }
    if (k == m_) {
      Emit();
      return;
    }
    for (std::size_t s = 0; s < n_; ++s) {
      if (used_[s] || !Consistent(k, s)) continue;
      used_[s] = true;
      assignment_[k] = static_cast<int>(s);
      Visit(k + 1, unseen);
      assignment_[k] = -1;
      used_[s] = false;
    }
    if (unseen < static_cast<int>(m_) - min_visible_) Visit(k + 1, unseen + 1);
  }

  // Every already assigned marker pair agrees with the scene pair within the tolerance.
  bool Consistent(std::size_t k, std::size_t s) const {
    for (std::size_t a = 0; a < k; ++a) {
      const int t = assignment_[a];
      if (t < 0) continue;
      const std::size_t ts = static_cast<std::size_t>(t);
      if (std::abs(scene_distance_[s * n_ + ts] - tool_distance_[k * m_ + a]) >
          tolerance_[s * n_ + ts]) {
        return false;
      }
    }
    return true;
  }

  // A sub-assignment of a kept candidate: the same physical match with markers left out. The
  // search assigns before it skips, so supersets are always emitted first.
  bool SubOfKept() const {
    return std::any_of(result_.candidates.begin(), result_.candidates.end(),
                       [&](const ToolCandidate& k) {
                         for (std::size_t a = 0; a < m_; ++a) {
                           if (assignment_[a] >= 0 && assignment_[a] != k.scene_index[a])
                             return false;
                         }
                         return true;
                       });
  }

  void Emit() {
    if (SubOfKept()) return;
    Points3d source, target;
    for (std::size_t a = 0; a < m_; ++a) {
      if (assignment_[a] < 0) continue;
      source.push_back(tool_.markers_in_tool[a]);
      target.push_back(scene_[static_cast<std::size_t>(assignment_[a])]);
    }
    if (static_cast<int>(source.size()) < min_visible_) return;
    RigidFitResult fit = FitRigid(source, target);
    if (fit.fre_rms_mm > options_.max_fre_mm) return;
    result_.candidates.push_back({assignment_, static_cast<int>(source.size()), std::move(fit)});
  }

  void DropSubAssignments() {
    std::vector<ToolCandidate>& c = result_.candidates;
    std::stable_sort(c.begin(), c.end(), [](const ToolCandidate& a, const ToolCandidate& b) {
      return a.visible > b.visible;
    });
    std::vector<ToolCandidate> kept;
    for (ToolCandidate& candidate : c) {
      const bool sub = std::any_of(kept.begin(), kept.end(), [&](const ToolCandidate& k) {
        if (k.visible <= candidate.visible) return false;
        for (std::size_t a = 0; a < m_; ++a) {
          if (candidate.scene_index[a] >= 0 && candidate.scene_index[a] != k.scene_index[a]) {
            return false;
          }
        }
        return true;
      });
      if (!sub) kept.push_back(std::move(candidate));
    }
    c = std::move(kept);
  }

  std::span<const Eigen::Vector3d> scene_;
  const ToolGeometry& tool_;
  int min_visible_;
  const CandidateSearchOptions& options_;
  std::size_t n_, m_;
  std::vector<double> scene_distance_, tolerance_, tool_distance_;
  std::vector<bool> used_;
  std::vector<int> assignment_;
  long nodes_ = 0;
  CandidateSearchResult result_;
};

}  // namespace

double MatchTolerance::AtMm(double range_mm) const {
  return std::clamp(base_mm + per_range * range_mm, min_mm, max_mm);
}

void MatchTolerance::Check() const {
  Require(base_mm >= 0.0 && per_range >= 0.0, "MatchTolerance: base_mm and per_range must be >= 0");
  Require(min_mm > 0.0 && max_mm >= min_mm, "MatchTolerance: need 0 < min_mm <= max_mm");
}

void CandidateSearchOptions::Check() const {
  tolerance.Check();
  Require(max_fre_mm > 0.0, "CandidateSearchOptions::max_fre_mm must be > 0");
  Require(max_nodes >= 1, "CandidateSearchOptions::max_nodes must be >= 1");
}

CandidateSearchResult FindToolCandidates(std::span<const Eigen::Vector3d> scene_in_ahat,
                                         const ToolGeometry& tool, int min_visible,
                                         const CandidateSearchOptions& options) {
  options.Check();
  Require(min_visible >= 3 && min_visible <= static_cast<int>(tool.markers_in_tool.size()),
          "FindToolCandidates: min_visible must be in [3, marker count]");
  return Search(scene_in_ahat, tool, min_visible, options).Run();
}

}  // namespace tofnav
