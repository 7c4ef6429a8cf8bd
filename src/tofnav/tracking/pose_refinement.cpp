// SPDX-License-Identifier: BSD-3-Clause
// Anisotropic pose refinement: per-marker ray, range and sigmas, then Gauss-Newton.
#include "tofnav/tracking/pose_refinement.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "tofnav/core/require.hpp"
#include "tofnav/markers/marker_centre.hpp"
#include "tofnav/tracking/ray_pose.hpp"

namespace tofnav {
namespace {

constexpr double kMaxPlanarityRmsMm = 1.0;  // a plate flatter than this carries its discs' plane
constexpr double kMinPlaneCosine = 0.2;     // grazing views keep the face-on range

// Per tool marker, the unit normal of its flat plate in the tool frame (MarkerPlates: the whole
// tool's plane, or one plane per plate of a tool built from several), or nullopt off a plate.
std::vector<std::optional<Eigen::Vector3d>> PlateNormals(const ToolGeometry& tool) {
  std::vector<std::optional<Eigen::Vector3d>> normals;
  for (const MarkerPlate& p : MarkerPlates(tool)) {
    normals.push_back(p.flatness_rms_mm <= kMaxPlanarityRmsMm
                          ? std::optional<Eigen::Vector3d>(p.normal_in_tool)
                          : std::nullopt);
  }
  return normals;
}

// Range and sigma of one marker: with `normal` (a flat disc's normal in ahat), each core pixel
// point t u meets the marker ray r in the disc plane at range t (n . u) / (n . r).
RayRangeObservation Observe(const DetectedMarker& d, const Eigen::Vector3d& centre,
                            const std::optional<Eigen::Vector3d>& normal,
                            const PoseRefinementOptions& options) {
  RayRangeObservation o;
  o.ray_in_ahat = d.ray_in_ahat;
  o.range_mm = centre.norm();
  std::vector<double> ranges;
  ranges.reserve(d.core.size());
  const double n_dot_r = normal ? normal->dot(d.ray_in_ahat) : 0.0;
  const bool on_plane = normal && std::abs(n_dot_r) > kMinPlaneCosine &&
                        std::all_of(d.core.begin(), d.core.end(), [](const CoreSample& s) {
                          return s.ray_in_ahat.norm() > 0.5f;
                        });
  for (const CoreSample& s : d.core) {
    const double t = s.range_mm;
    ranges.push_back(on_plane ? t * normal->dot(s.ray_in_ahat.cast<double>().normalized()) / n_dot_r
                              : t);
  }
  if (on_plane && !ranges.empty()) {
    std::vector<double> copy = ranges;
    o.range_mm = TrimmedMean(copy);
  }
  o.range_sigma_mm = MeanSigmaMm(ranges, options.range_sigma_floor_mm);
  o.lateral_sigma_mm = options.lateral_sigma_px * d.pixel_pitch_rad * o.range_mm;
  return o;
}

}  // namespace

double MeanSigmaMm(std::vector<double>& values, double floor_mm) {
  if (values.size() < 2) return std::max(floor_mm, 1.0);
  const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  const double median = *mid;
  for (double& v : values) v = std::abs(v - median);
  std::nth_element(values.begin(), mid, values.end());
  return std::max(floor_mm, 1.4826 * *mid / std::sqrt(static_cast<double>(values.size())));
}

void PoseRefinementOptions::Check() const {
  Require(lateral_sigma_px > 0.0, "PoseRefinementOptions::lateral_sigma_px must be > 0");
  Require(range_sigma_floor_mm > 0.0, "PoseRefinementOptions::range_sigma_floor_mm must be > 0");
  Require(passes >= 1, "PoseRefinementOptions::passes must be >= 1");
}

std::optional<Rigid3d> RefineToolPose(std::span<const DetectedMarker> detections,
                                      std::span<const int> marker_detection,
                                      const ToolGeometry& tool, const Points3d& centres,
                                      const Rigid3d& initial_ahat_from_tool,
                                      const PoseRefinementOptions& options,
                                      std::span<const double> extra_lateral_sigma_mm) {
  options.Check();
  Require(
      extra_lateral_sigma_mm.empty() || extra_lateral_sigma_mm.size() == marker_detection.size(),
      "RefineToolPose: extra_lateral_sigma_mm must hold one sigma per tool marker");
  std::vector<std::optional<Eigen::Vector3d>> normals_in_tool(marker_detection.size());
  if (options.disc_plane_ranges && tool.marker_type == MarkerType::kDisc) {
    normals_in_tool = PlateNormals(tool);
  }
  Points3d markers;
  for (std::size_t k = 0; k < marker_detection.size(); ++k) {
    const int s = marker_detection[k];
    if (s < 0) continue;
    if (!(detections[static_cast<std::size_t>(s)].pixel_pitch_rad > 0.0)) return std::nullopt;
    markers.push_back(tool.markers_in_tool[k]);
  }
  const bool on_plates = std::any_of(normals_in_tool.begin(), normals_in_tool.end(),
                                     [](const auto& n) { return n.has_value(); });
  Rigid3d pose = initial_ahat_from_tool;
  const int passes = on_plates ? options.passes : 1;
  for (int pass = 0; pass < passes; ++pass) {
    std::vector<RayRangeObservation> observations;
    for (std::size_t k = 0; k < marker_detection.size(); ++k) {
      const int s = marker_detection[k];
      if (s < 0) continue;
      std::optional<Eigen::Vector3d> normal;
      if (normals_in_tool[k]) normal = pose.rotation * *normals_in_tool[k];
      const auto i = static_cast<std::size_t>(s);
      RayRangeObservation o = Observe(detections[i], centres[i], normal, options);
      if (!extra_lateral_sigma_mm.empty()) {
        o.lateral_sigma_mm = std::hypot(o.lateral_sigma_mm, extra_lateral_sigma_mm[k]);
      }
      observations.push_back(o);
    }
    const RayPoseResult refined = EstimatePoseFromRaysAndRanges(markers, observations, pose);
    if (!refined.converged) return std::nullopt;
    pose = refined.ahat_from_tool;
  }
  return pose;
}

}  // namespace tofnav
