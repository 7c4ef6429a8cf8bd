// SPDX-License-Identifier: BSD-3-Clause
// DefineTool: distance-matched frames averaged by generalised Procrustes (docs/tracking.md 10).
#include "tofnav/tracking/tool_definition.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "tofnav/core/dense_solvers.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/core/rigid_fit.hpp"
#include "tofnav/markers/marker_centre.hpp"
#include "tofnav/tracking/correspondence.hpp"

namespace tofnav {
namespace {

constexpr double kMinObservedFraction = 0.5;  // markers seen in fewer of the used frames drop
constexpr double kOutlierFloorMm = 0.1;       // never reject observations closer than this

int ModalCount(const std::vector<Points3d>& frames) {
  std::map<std::size_t, int> histogram;
  for (const Points3d& f : frames) {
    if (f.size() >= 3) ++histogram[f.size()];
  }
  Require(!histogram.empty(), "DefineTool: no frame has 3 or more markers");
  auto best = histogram.begin();
  for (auto it = histogram.begin(); it != histogram.end(); ++it) {
    if (it->second >= best->second) best = it;  // ties: the larger count
  }
  return static_cast<int>(best->first);
}

std::vector<double> SortedDistances(const Points3d& p) {
  std::vector<double> d;
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (std::size_t j = i + 1; j < p.size(); ++j) d.push_back((p[i] - p[j]).norm());
  }
  std::sort(d.begin(), d.end());
  return d;
}

// The frame with `count` markers whose sorted distances lie closest to the elementwise median.
Points3d ReferenceFrame(const std::vector<Points3d>& frames, std::size_t count) {
  std::vector<std::vector<double>> distances;
  std::vector<std::size_t> index;
  for (std::size_t f = 0; f < frames.size(); ++f) {
    if (frames[f].size() != count) continue;
    distances.push_back(SortedDistances(frames[f]));
    index.push_back(f);
  }
  Require(!index.empty(), "DefineTool: no frame has marker_count markers");
  std::vector<double> median(distances[0].size());
  for (std::size_t k = 0; k < median.size(); ++k) {
    std::vector<double> column;
    for (const std::vector<double>& d : distances) column.push_back(d[k]);
    std::nth_element(column.begin(),
                     column.begin() + static_cast<std::ptrdiff_t>(column.size() / 2), column.end());
    median[k] = column[column.size() / 2];
  }
  std::size_t best = 0;
  double best_deviation = INFINITY;
  for (std::size_t i = 0; i < distances.size(); ++i) {
    double deviation = 0.0;
    for (std::size_t k = 0; k < median.size(); ++k) {
      deviation = std::max(deviation, std::abs(distances[i][k] - median[k]));
    }
    if (deviation < best_deviation) best_deviation = deviation, best = i;
  }
  return frames[index[best]];
}

// The markers in their own frame: centroid origin, principal axes, x and y signs fixed by the
// first marker with a clear coordinate on them, z = x cross y.
Points3d Canonical(const Points3d& points) {
  const PrincipalAxes principal = ComputePrincipalAxes(points);
  const Eigen::Vector3d& mean = principal.centroid;
  Eigen::Matrix3d axes = principal.axes;  // columns: principal directions
  for (int a = 0; a < 2; ++a) {
    for (const Eigen::Vector3d& p : points) {
      const double c = (p - mean).dot(axes.col(a));
      if (std::abs(c) > 1e-3) {
        if (c < 0.0) axes.col(a) *= -1.0;
        break;
      }
    }
  }
  axes.col(2) = axes.col(0).cross(axes.col(1));
  Points3d out;
  for (const Eigen::Vector3d& p : points) out.push_back(axes.transpose() * (p - mean));
  return out;
}

struct FrameMatch {
  std::vector<int> scene_index;  // per model marker
  Rigid3d ahat_from_model;
};

std::optional<FrameMatch> MatchFrame(const Points3d& centres, const ToolGeometry& model,
                                     const ToolDefinitionOptions& options) {
  if (centres.size() < 3) return std::nullopt;
  CandidateSearchOptions search;
  const double tol = options.match_tolerance_mm;
  search.tolerance = {tol, 0.0, tol, tol};
  search.max_fre_mm = options.max_fre_mm;
  const CandidateSearchResult r = FindToolCandidates(centres, model, 3, search);
  if (r.candidates.empty()) return std::nullopt;
  const auto best = std::min_element(
      r.candidates.begin(), r.candidates.end(), [](const ToolCandidate& a, const ToolCandidate& b) {
        return a.visible != b.visible ? a.visible > b.visible : a.fit.fre_rms_mm < b.fit.fre_rms_mm;
      });
  return FrameMatch{best->scene_index, best->fit.target_from_source};
}

}  // namespace

void ToolDefinitionOptions::Check() const {
  Require(marker_diameter_mm > 0.0, "ToolDefinitionOptions::marker_diameter_mm must be > 0");
  Require(std::isfinite(marker_entrance_gain_mm_per_rad),
          "ToolDefinitionOptions::marker_entrance_gain_mm_per_rad must be finite");
  Require(marker_count == 0 || marker_count >= 3,
          "ToolDefinitionOptions::marker_count must be 0 or >= 3");
  Require(match_tolerance_mm > 0.0 && max_fre_mm > 0.0,
          "ToolDefinitionOptions::match_tolerance_mm and max_fre_mm must be > 0");
  Require(outlier_factor > 1.0, "ToolDefinitionOptions::outlier_factor must be > 1");
  Require(min_frames >= 1 && iterations >= 1,
          "ToolDefinitionOptions::min_frames and iterations must be >= 1");
}

ToolDefinitionResult DefineTool(std::span<const std::vector<DetectedMarker>> frames,
                                const ToolDefinitionOptions& options) {
  options.Check();
  const double radius =
      options.marker_type == MarkerType::kSphere ? options.marker_diameter_mm / 2 : 0.0;
  std::vector<Points3d> centres;
  for (const std::vector<DetectedMarker>& f : frames) {
    if (radius > 0.0 && options.marker_entrance_gain_mm_per_rad != 0.0) {
      std::vector<DetectedMarker> corrected = f;
      for (DetectedMarker& m : corrected) {
        ShiftSphereEntranceAngles(m, m.ray_in_ahat * (m.surface_range_mm + radius), radius,
                                  options.marker_entrance_gain_mm_per_rad);
      }
      centres.push_back(MarkerCentres(corrected, radius));
    } else {
      centres.push_back(MarkerCentres(f, radius));
    }
  }
  const int count = options.marker_count > 0 ? options.marker_count : ModalCount(centres);
  ToolGeometry model;
  model.name = options.name;
  model.markers_in_tool = Canonical(ReferenceFrame(centres, static_cast<std::size_t>(count)));
  model.marker_type = options.marker_type;
  model.marker_diameter_mm = options.marker_diameter_mm;
  ToolDefinitionResult result;
  std::vector<std::optional<FrameMatch>> matches(centres.size());
  for (int iteration = 0; iteration < options.iterations; ++iteration) {
    for (std::size_t f = 0; f < centres.size(); ++f)
      matches[f] = MatchFrame(centres[f], model, options);
    // Observations of each marker in the model frame, then a trimmed mean.
    const std::size_t m = model.markers_in_tool.size();
    std::vector<Points3d> observed(m);
    for (std::size_t f = 0; f < centres.size(); ++f) {
      if (!matches[f]) continue;
      const Rigid3d model_from_ahat = matches[f]->ahat_from_model.Inverse();
      for (std::size_t k = 0; k < m; ++k) {
        const int s = matches[f]->scene_index[k];
        if (s >= 0)
          observed[k].push_back(model_from_ahat * centres[f][static_cast<std::size_t>(s)]);
      }
    }
    const int used = static_cast<int>(
        std::count_if(matches.begin(), matches.end(), [](const auto& x) { return x.has_value(); }));
    Require(used >= options.min_frames,
            "DefineTool: only " + std::to_string(used) + " frames match the reference geometry");
    Points3d means;
    result.marker_rms_mm.clear();
    result.marker_observations.clear();
    double sum2 = 0.0;
    int total = 0;
    for (std::size_t k = 0; k < m; ++k) {
      if (static_cast<double>(observed[k].size()) < kMinObservedFraction * used) continue;
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      for (const Eigen::Vector3d& p : observed[k]) mean += p;
      mean /= static_cast<double>(observed[k].size());
      double rms = 0.0;
      for (const Eigen::Vector3d& p : observed[k]) rms += (p - mean).squaredNorm();
      rms = std::sqrt(rms / static_cast<double>(observed[k].size()));
      const double limit = std::max(kOutlierFloorMm, options.outlier_factor * rms);
      Eigen::Vector3d trimmed = Eigen::Vector3d::Zero();
      int n = 0;
      double trimmed2 = 0.0;
      for (const Eigen::Vector3d& p : observed[k]) {
        if ((p - mean).norm() > limit) continue;
        trimmed += p;
        trimmed2 += (p - mean).squaredNorm();
        ++n;
      }
      means.push_back(trimmed / n);
      result.marker_rms_mm.push_back(std::sqrt(trimmed2 / n));
      result.marker_observations.push_back(n);
      sum2 += trimmed2;
      total += n;
    }
    Require(means.size() >= 3, "DefineTool: fewer than 3 markers are seen in half the frames");
    model.markers_in_tool = Canonical(means);
    result.definition_rms_mm = std::sqrt(sum2 / total);
    result.frames_used = used;
  }
  result.frames_rejected = static_cast<int>(centres.size()) - result.frames_used;
  result.tool = model;
  result.ahat_from_tool.assign(centres.size(), std::nullopt);
  for (std::size_t f = 0; f < centres.size(); ++f) {
    const std::optional<FrameMatch> match = MatchFrame(centres[f], model, options);
    if (match) result.ahat_from_tool[f] = match->ahat_from_model;
  }
  result.tool.Check();
  return result;
}

}  // namespace tofnav
