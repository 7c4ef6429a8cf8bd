// SPDX-License-Identifier: BSD-3-Clause
// Surface registration: coarse alignment, fine ICP, quality (Sec. III-B).
#include "tofnav/registration/register_surface.hpp"

#include <algorithm>
#include <numeric>

#include "tofnav/core/require.hpp"
#include "tofnav/registration/sampling.hpp"

namespace tofnav {

namespace {

constexpr double kSamePoseRad = 0.035;  // fine poses closer than 2 deg and 2 mm are one solution
constexpr double kSamePoseMm = 2.0;

/// Robust cost of an ICP solution: mean squared residual with unmatched points at the gate.
double RobustCost(const IcpResult& icp, double gate_mm) {
  return icp.inlier_fraction * icp.rmse_mm * icp.rmse_mm +
         (1.0 - icp.inlier_fraction) * gate_mm * gate_mm;
}

bool SamePose(const Rigid3d& a, const Rigid3d& b, const Eigen::Vector3d& point) {
  return RotationDistanceRad(a, b) <= kSamePoseRad && (a * point - b * point).norm() <= kSamePoseMm;
}

}  // namespace

void RegisterSurfaceOptions::Check() const {
  Require(sample_spacing_mm > 0.0, "RegisterSurfaceOptions.sample_spacing_mm must be > 0");
  Require(fine_candidates >= 1, "RegisterSurfaceOptions.fine_candidates must be >= 1");
  source_normals.Check();
  coarse.Check();
  icp.Check();
  thresholds.Check();
}

RegisterSurfaceResult RegisterSurface(const PointCloud& reconstruction_in_tool,
                                      const SurfaceIndex& skin_in_image,
                                      std::span<const Eigen::Vector3d> targets_in_image,
                                      const RegisterSurfaceOptions& options,
                                      const std::optional<Rigid3d>& tool_from_image_guess) {
  options.Check();
  RegisterSurfaceResult result;
  const SurfaceIndex reconstruction(reconstruction_in_tool, options.source_normals);
  const std::vector<std::uint32_t> fine =
      VoxelSubsample(reconstruction.points(), options.sample_spacing_mm);
  const Points3d points = Gather(reconstruction.points(), fine);
  const Points3d normals = Gather(reconstruction.normals(), fine);

  std::vector<Rigid3d> starts;  // image_from_tool
  if (tool_from_image_guess) {
    starts.push_back(tool_from_image_guess->Inverse());
  } else {
    result.coarse = AlignCoarse(reconstruction, skin_in_image, options.coarse);
    for (const CoarseCandidate& c : result.coarse.candidates) {
      if (static_cast<int>(starts.size()) < options.fine_candidates)
        starts.push_back(c.target_from_source);
    }
    if (starts.empty()) {
      result.quality.status = RegistrationStatus::kNoOverlap;
      result.quality.message =
          "the reconstruction does not overlap the skin anywhere (no coarse placement)";
      return result;
    }
  }
  // Fine ICP from each start; keep the lowest robust cost, and measure how close the best
  // distinct alternative comes (a symmetric or featureless patch fits in several poses).
  const double gate_mm =
      std::max(options.icp.max_distance_schedule_mm.back(), skin_in_image.spacing_mm());
  std::vector<IcpResult> fits;
  for (const Rigid3d& start : starts) {
    fits.push_back(AlignPointToPlane(points, normals, skin_in_image, start, options.icp));
  }
  const auto best = static_cast<std::size_t>(
      std::min_element(fits.begin(), fits.end(),
                       [&](const IcpResult& a, const IcpResult& b) {
                         return RobustCost(a, gate_mm) < RobustCost(b, gate_mm);
                       }) -
      fits.begin());
  const Eigen::Vector3d centroid =
      std::accumulate(points.begin(), points.end(), Eigen::Vector3d(0, 0, 0)) /
      static_cast<double>(std::max<std::size_t>(points.size(), 1));
  double ambiguity = 0.0, ambiguity_shift_mm = 0.0;
  const Rigid3d& best_pose = fits[best].target_from_source;
  for (std::size_t i = 0; i < fits.size(); ++i) {
    if (i == best || SamePose(fits[i].target_from_source, best_pose, centroid)) continue;
    const double cost = RobustCost(fits[i], gate_mm), best_cost = RobustCost(fits[best], gate_mm);
    const double ratio = cost <= best_cost ? 1.0 : best_cost / cost;
    if (ratio <= ambiguity) continue;
    ambiguity = ratio;
    // Where the alternative would put what the best pose puts at each target (image frame).
    const Rigid3d alternative_from_best = fits[i].target_from_source * best_pose.Inverse();
    ambiguity_shift_mm = 0.0;
    for (const Eigen::Vector3d& q : targets_in_image) {
      ambiguity_shift_mm = std::max(ambiguity_shift_mm, (alternative_from_best * q - q).norm());
    }
    if (targets_in_image.empty()) {
      const Eigen::Vector3d c = best_pose * centroid;
      ambiguity_shift_mm = (alternative_from_best * c - c).norm();
    }
  }
  result.icp = std::move(fits[best]);
  result.quality = AssessRegistration(result.icp, points, targets_in_image, options.thresholds,
                                      ambiguity, ambiguity_shift_mm);
  result.tool_from_image = result.icp.target_from_source.Inverse();
  return result;
}

}  // namespace tofnav
