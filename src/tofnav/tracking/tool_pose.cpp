// SPDX-License-Identifier: BSD-3-Clause
// Multi-tool arbitration, temporal prior and ambiguity detection (docs/tracking.md 7.3, 9.4, 9.7).
#include "tofnav/tracking/tool_pose.hpp"

#include <algorithm>
#include <cmath>

#include "tofnav/core/require.hpp"
#include "tofnav/markers/marker_centre.hpp"

namespace tofnav {
namespace {

struct Scored {
  std::size_t tool = 0;
  std::size_t candidate = 0;
  double score = 0.0;
  bool dominated = false;  // a candidate of another tool explains its blobs and more (Dominates)
  /// The frame's images show empty space where it puts an unmatched marker (MarkerVoidTest):
  /// never accepted, but still a rival, so that refusing it can only take a pose away.
  bool refused = false;
};

bool Uses(const ToolCandidate& c, const std::vector<bool>& used) {
  return std::any_of(c.scene_index.begin(), c.scene_index.end(),
                     [&](int s) { return s >= 0 && used[static_cast<std::size_t>(s)]; });
}

bool Shares(const ToolCandidate& a, const ToolCandidate& b) {
  return std::any_of(a.scene_index.begin(), a.scene_index.end(), [&](int s) {
    return s >= 0 &&
           std::find(b.scene_index.begin(), b.scene_index.end(), s) != b.scene_index.end();
  });
}

// True when `other` claims a strict subset of the detections of `full`, and is itself not a whole
// tool: `full` explains each of those blobs and more, with more coincident distances, while
// `other` must also claim an occlusion of its unseen markers. A 3-marker triangle of one tool that
// happens to fit 3 markers of another (at 700 mm the tolerance admits that) is then no rival, also
// where `full` is a headframe of two plates with one of them out of view (4 of 8 markers: its
// occlusion penalty had let the instrument's triangle on the seen plate win, docs/tracking.md 9.4).
bool Dominates(const ToolCandidate& full, const ToolCandidate& other) {
  if (full.visible <= other.visible ||
      other.visible >= static_cast<int>(other.scene_index.size())) {
    return false;
  }
  return std::all_of(other.scene_index.begin(), other.scene_index.end(), [&](int s) {
    return s < 0 ||
           std::find(full.scene_index.begin(), full.scene_index.end(), s) != full.scene_index.end();
  });
}

// True when the candidate leaves a marker unmatched where the images show empty space.
bool PutsAMarkerInTheVoid(const ToolGeometry& tool, const ToolCandidate& c,
                          const MarkerVoidTest& void_test) {
  for (std::size_t k = 0; k < tool.markers_in_tool.size() && k < c.scene_index.size(); ++k) {
    if (c.scene_index[k] >= 0) continue;
    const Eigen::Vector3d centre = c.fit.target_from_source * tool.markers_in_tool[k];
    if (void_test.IsVoid(centre, tool.marker_diameter_mm)) return true;
  }
  return false;
}

// Replaces the matched Kabsch pose by FitToolMarkers': the markers it should use, refined.
void FitUsed(std::span<const DetectedMarker> detections, const Points3d& centres,
             const ToolGeometry& tool, const ToolPoseOptions& options,
             std::span<const DroppedBlob> dropped, ToolPoseResult& r) {
  RobustPose fit = FitToolMarkers(detections, r.marker_detection, tool, centres, options.refinement,
                                  options.robust);
  ExplainUnseenMarkers(fit.ahat_from_tool, tool, dropped, fit.use);
  r.ahat_from_tool = fit.ahat_from_tool;
  r.marker_use = std::move(fit.use);
  r.used_markers =
      static_cast<int>(std::count_if(r.marker_use.begin(), r.marker_use.end(), InPose));
  r.residuals_mm = std::move(fit.residuals_mm);
  r.fre_rms_mm = fit.fre_rms_mm;
  r.noise_chi2 = fit.chi2;
  r.noise_chi2_limit = fit.chi2_limit;
  r.outliers_checked = fit.outliers_checked;
  r.rotation_sd_rad = fit.rotation_sd_rad;
  r.position_sd_mm = fit.position_sd_mm;
}

// The matched markers' ranges shortened by gain x their entrance angle under the fitted pose
// (a disc: its own plate's plane against its ray, MarkerPlaneNormals; a sphere: per core pixel),
// and the pose fitted again on them: one step suffices, a 1 deg pose error moves beta by 1 deg and
// the range by gain x 0.017 mm.
void RefitForEntranceAngles(std::span<const DetectedMarker> detections, const ToolGeometry& tool,
                            const ToolPoseOptions& options, std::span<const DroppedBlob> dropped,
                            ToolPoseResult& r) {
  const double gain = options.marker_entrance_gain_mm_per_rad;
  const std::vector<Eigen::Vector3d> normals_in_tool = MarkerPlaneNormals(tool);
  std::vector<DetectedMarker> corrected(detections.begin(), detections.end());
  for (std::size_t k = 0; k < r.marker_detection.size(); ++k) {
    const int d = r.marker_detection[k];
    if (d < 0) continue;
    DetectedMarker& m = corrected[static_cast<std::size_t>(d)];
    if (tool.marker_type == MarkerType::kSphere) {
      ShiftSphereEntranceAngles(m, *r.ahat_from_tool * tool.markers_in_tool[k],
                                tool.SurfaceToCentreMm(), gain);
    } else {
      const Eigen::Vector3d normal = r.ahat_from_tool->rotation * normals_in_tool[k];
      ShiftMarkerRange(m, -gain * TapeEntranceAngleRad(normal, m.ray_in_ahat));
    }
  }
  FitUsed(corrected, MarkerCentres(corrected, tool.SurfaceToCentreMm()), tool, options, dropped, r);
}

class Arbiter {
 public:
  Arbiter(std::span<const Points3d> centres, std::span<const ToolGeometry> tools,
          std::span<const std::optional<Rigid3d>> predicted, const ToolPoseOptions& options,
          const MarkerVoidTest* void_test = nullptr)
      : tools_(tools), options_(options), results_(tools.size()), resolved_(tools.size(), false) {
    for (std::size_t t = 0; t < tools.size(); ++t) {
      results_[t].marker_use.assign(tools[t].markers_in_tool.size(), MarkerUse::kUnseen);
    }
    detection_count_ = centres.empty() ? 0 : centres[0].size();
    used_.assign(detection_count_, false);
    for (std::size_t t = 0; t < tools.size(); ++t) {
      const ToolGeometry& tool = tools[t];
      CandidateSearchOptions search_options;
      search_options.tolerance = options.tolerance;
      search_options.max_fre_mm = tool.max_fre_mm > 0.0 ? tool.max_fre_mm : options.max_fre_mm;
      search_options.max_nodes = options.max_search_nodes;
      searches_.push_back(FindToolCandidates(centres[t], tool, tool.min_visible, search_options));
      results_[t].candidate_count = static_cast<int>(searches_[t].candidates.size());
      const std::optional<Rigid3d> prior = predicted.empty() ? std::nullopt : predicted[t];
      for (std::size_t c = 0; c < searches_[t].candidates.size(); ++c) {
        const bool refused = void_test && options.refuse_void_poses &&
                             PutsAMarkerInTheVoid(tool, searches_[t].candidates[c], *void_test);
        if (refused) ++results_[t].candidates_refused_void;
        scored_.push_back({t, c, Score(tool, searches_[t].candidates[c], prior), false, refused});
      }
    }
    std::stable_sort(scored_.begin(), scored_.end(),
                     [](const Scored& a, const Scored& b) { return a.score < b.score; });
    for (Scored& s : scored_) {
      s.dominated = std::any_of(scored_.begin(), scored_.end(), [&](const Scored& o) {
        return o.tool != s.tool && Dominates(Candidate(o), Candidate(s));
      });
    }
  }

  std::vector<ToolPoseResult> Run() {
    for (const Scored& s : scored_) {
      if (resolved_[s.tool] || Uses(Candidate(s), used_) || s.dominated || s.refused) continue;
      Decide(s);
    }
    const int free = static_cast<int>(std::count(used_.begin(), used_.end(), false));
    for (std::size_t t = 0; t < tools_.size(); ++t) {
      if (resolved_[t]) continue;
      results_[t].status = searches_[t].truncated         ? ToolStatus::kAmbiguous
                           : free < tools_[t].min_visible ? ToolStatus::kTooFewMarkers
                                                          : ToolStatus::kOutOfView;
    }
    return std::move(results_);
  }

 private:
  const ToolCandidate& Candidate(const Scored& s) const {
    return searches_[s.tool].candidates[s.candidate];
  }

  // Ranking of docs/tracking.md 9.4: FRE + occlusion penalty + capped temporal prior.
  double Score(const ToolGeometry& tool, const ToolCandidate& c,
               const std::optional<Rigid3d>& prior) const {
    const int unseen = static_cast<int>(tool.markers_in_tool.size()) - c.visible;
    double score = c.fit.fre_rms_mm + options_.occlusion_penalty_mm * unseen;
    if (prior) {
      double distance = 0.0;
      for (const Eigen::Vector3d& m : tool.markers_in_tool) {
        distance += (c.fit.target_from_source * m - *prior * m).norm();
      }
      distance /= static_cast<double>(tool.markers_in_tool.size());
      score += options_.prior_weight * std::min(distance, options_.prior_cap_mm);
    }
    return score;
  }

  bool Distinct(const ToolCandidate& a, const ToolCandidate& b) const {
    const Rigid3d& pa = a.fit.target_from_source;
    const Rigid3d& pb = b.fit.target_from_source;
    return RotationDistanceRad(pa, pb) > options_.distinct_rotation_rad ||
           TranslationDistanceMm(pa, pb) > options_.distinct_translation_mm;
  }

  // The best remaining candidate of its tool: accept it unless a distinct alternative of the same
  // tool, or another tool's candidate on the same detections, scores within the margin.
  void Decide(const Scored& best) {
    const ToolCandidate& c = Candidate(best);
    double margin = std::numeric_limits<double>::infinity();
    std::vector<std::size_t> rivals;
    for (const Scored& s : scored_) {
      if (&Candidate(s) == &c || resolved_[s.tool] || Uses(Candidate(s), used_)) continue;
      const bool rival =
          s.tool == best.tool ? Distinct(c, Candidate(s)) : Shares(c, Candidate(s)) && !s.dominated;
      if (!rival) continue;
      margin = std::min(margin, s.score - best.score);
      if (s.tool != best.tool && s.score - best.score < options_.ambiguity_margin_mm) {
        rivals.push_back(s.tool);
      }
    }
    ToolPoseResult& r = results_[best.tool];
    r.second_best_margin_mm = margin;
    resolved_[best.tool] = true;
    if (margin < options_.ambiguity_margin_mm || searches_[best.tool].truncated) {
      r.status = ToolStatus::kAmbiguous;
      for (const std::size_t t : rivals) {
        resolved_[t] = true;
        results_[t].status = ToolStatus::kAmbiguous;
      }
      return;
    }
    const std::size_t marker_count = tools_[best.tool].markers_in_tool.size();
    r.status = c.visible == static_cast<int>(marker_count) ? ToolStatus::kOk
                                                           : ToolStatus::kPartiallyOccluded;
    r.ahat_from_tool = c.fit.target_from_source;
    r.marker_detection = c.scene_index;
    r.visible_markers = c.visible;
    r.used_markers = c.visible;
    for (std::size_t k = 0; k < marker_count; ++k) {
      if (c.scene_index[k] >= 0) r.marker_use[k] = MarkerUse::kUsed;
    }
    r.fre_rms_mm = c.fit.fre_rms_mm;
    r.residuals_mm = c.fit.residuals_mm;
    for (const int s : c.scene_index) {
      if (s >= 0) used_[static_cast<std::size_t>(s)] = true;
    }
  }

  std::span<const ToolGeometry> tools_;
  const ToolPoseOptions& options_;
  std::size_t detection_count_ = 0;
  std::vector<CandidateSearchResult> searches_;
  std::vector<Scored> scored_;
  std::vector<ToolPoseResult> results_;
  std::vector<bool> resolved_;
  std::vector<bool> used_;
};

}  // namespace

const char* ToString(ToolStatus status) {
  switch (status) {
    case ToolStatus::kOk:
      return "ok";
    case ToolStatus::kPartiallyOccluded:
      return "partially_occluded";
    case ToolStatus::kAmbiguous:
      return "ambiguous";
    case ToolStatus::kTooFewMarkers:
      return "too_few_markers";
    case ToolStatus::kOutOfView:
      return "out_of_view";
  }
  return "unknown";
}

void ToolPoseOptions::Check() const {
  tolerance.Check();
  refinement.Check();
  robust.Check();
  Require(std::isfinite(marker_entrance_gain_mm_per_rad),
          "ToolPoseOptions::marker_entrance_gain_mm_per_rad must be finite");
  Require(max_fre_mm > 0.0, "ToolPoseOptions::max_fre_mm must be > 0");
  Require(occlusion_penalty_mm >= 0.0, "ToolPoseOptions::occlusion_penalty_mm must be >= 0");
  Require(prior_weight >= 0.0 && prior_cap_mm >= 0.0,
          "ToolPoseOptions::prior_weight and prior_cap_mm must be >= 0");
  Require(ambiguity_margin_mm >= 0.0, "ToolPoseOptions::ambiguity_margin_mm must be >= 0");
  Require(distinct_rotation_rad > 0.0 && distinct_translation_mm > 0.0,
          "ToolPoseOptions::distinct_rotation_rad and distinct_translation_mm must be > 0");
  Require(max_search_nodes >= 1, "ToolPoseOptions::max_search_nodes must be >= 1");
}

std::vector<ToolPoseResult> EstimateToolPoses(
    std::span<const DetectedMarker> detections, std::span<const ToolGeometry> tools,
    std::span<const std::optional<Rigid3d>> predicted_ahat_from_tool,
    const ToolPoseOptions& options, std::span<const DroppedBlob> dropped,
    const MarkerVoidTest* void_test) {
  options.Check();
  Require(predicted_ahat_from_tool.empty() || predicted_ahat_from_tool.size() == tools.size(),
          "EstimateToolPoses: predicted_ahat_from_tool must be empty or one per tool");
  std::vector<Points3d> centres;
  centres.reserve(tools.size());
  for (const ToolGeometry& tool : tools) {
    tool.Check();
    centres.push_back(MarkerCentres(detections, tool.SurfaceToCentreMm()));
  }
  std::vector<ToolPoseResult> results =
      Arbiter(centres, tools, predicted_ahat_from_tool, options, void_test).Run();
  for (std::size_t t = 0; t < tools.size(); ++t) {
    if (!results[t].ahat_from_tool) continue;
    FitUsed(detections, centres[t], tools[t], options, dropped, results[t]);
    if (options.marker_entrance_gain_mm_per_rad != 0.0)
      RefitForEntranceAngles(detections, tools[t], options, dropped, results[t]);
  }
  return results;
}

ToolPoseResult EstimateToolPose(std::span<const Eigen::Vector3d> centres_in_ahat,
                                const ToolGeometry& tool, const ToolPoseOptions& options) {
  options.Check();
  tool.Check();
  const Points3d centres(centres_in_ahat.begin(), centres_in_ahat.end());
  return Arbiter(std::span<const Points3d>(&centres, 1), std::span<const ToolGeometry>(&tool, 1),
                 {}, options)
      .Run()[0];
}

}  // namespace tofnav
