// SPDX-License-Identifier: BSD-3-Clause
// The paper's method as published: each stage's options (docs/paper_method.md says, stage by
// stage, what the paper describes and which of tofnav's additions each line turns off).
#include "tofnav/pipeline/paper_method.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>

namespace tofnav {
namespace {

// Keller's on-device tracker matches pairwise distances within a constant 4 mm (docs/tracking.md
// 7.1); tofnav's tolerance grows with the range from 1.5 mm.
constexpr double kPaperMatchToleranceMm = 4.0;
// One correspondence gate for the ICP from a hand placement of about 5 mm / 5 deg: wide enough
// for the placement's largest offsets at the head's rim (5 mm + 5 deg over 60 mm ~ 10 mm).
constexpr double kPaperIcpGateMm = 10.0;

}  // namespace

const char* ToString(Method method) { return method == Method::kPaper ? "paper" : "tofnav"; }

std::optional<Method> ParseMethod(std::string_view name) {
  if (name == "tofnav") return Method::kTofnav;
  if (name == "paper") return Method::kPaper;
  return std::nullopt;
}

void UsePaperIdentification(IdentifyRecordingOptions& options) {
  DepthErrorModel start;  // Eq. (3): C1 + C2 d + C3 theta, from 0
  start.multipath.enabled = false;
  options.start = start;
  options.cross_validate_folds = 0;
  options.exclude_tools.clear();
  options.reference_tool.reset();  // Err_C registers each frame on its own
  options.smooth_reference_rotation = false;
  options.placement_subsets = 0;
  IdentificationSampling& sampling = options.sampling;
  sampling.segmentation.head_region.enabled = false;  // marker, transition, the rest is head
  sampling.multipath.enabled = false;
  IdentificationOptions& fit = options.identification;
  fit.huber_scale_mm = 0.0;  // Eq. (7) is a plain sum of squares
  fit.reject_outlier_markers = false;
  fit.centre_references = false;  // C1 at theta = 0, as Eq. (3) writes it
  fit.foreground.enabled = false;
  fit.head_surface_weight = 0.0;
  fit.joint_smoothness_weight = 1.0;  // Eq. (7): Err_S and Err_C as the paper weighs them
  fit.fit_cyclic_period_mm = 0.0;
}

void UsePaperTracking(ToolPoseOptions& options) {
  options.tolerance = {.base_mm = kPaperMatchToleranceMm,
                       .per_range = 0.0,
                       .min_mm = kPaperMatchToleranceMm,
                       .max_mm = kPaperMatchToleranceMm};
  options.refinement.enabled = false;
  options.robust.drop_damaged = false;
  options.robust.check_outliers = false;
  options.prior_weight = 0.0;
  options.refuse_void_poses = false;
}

void UsePaperTracking(ToolTrackerOptions& options) {
  UsePaperTracking(options.pose);
  options.filter_enabled = false;
  options.inflate_noise_by_fit = false;
}

void UsePaperTracking(NavigatorOptions& options) {
  UsePaperTracking(options.tracking);
  options.check_pose_jumps = false;
}

void UsePaperReconstruction(ReconstructOptions& options) {
  UsePaperTracking(options.pose);
  options.check_pose_consistency = false;
  options.smooth_rotation = false;
  options.model_check.enabled = false;
  options.head_region.enabled = false;
  options.min_observed_frames = 0.0;
  options.min_observed_fraction = 0.0;
  options.boundary_rings_removed = 0;
  options.ab_weight_reference = 0.0;
  options.multipath_weight_ratio = 0.0;
}

void UsePaperRegistration(RegisterSurfaceOptions& options) {
  options.icp.max_distance_schedule_mm = {kPaperIcpGateMm};
  options.icp.max_normal_angle_rad = std::numbers::pi;
  options.icp.loss = RobustLoss::kSquared;
  RegistrationThresholds& t = options.thresholds;  // no refusal: every figure passes
  const double huge = std::numeric_limits<double>::max();
  t.max_rmse_mm = huge;
  t.min_inlier_fraction = 0.0;
  t.min_rotation_conditioning = 0.0;
  t.min_translation_conditioning = 0.0;
  t.max_predicted_tre_mm = huge;
  t.max_ambiguity = 1.0;
}

Rigid3d HandPlacedStart(const Rigid3d& true_tool_from_image, const Eigen::Vector3d& centre_in_image,
                        std::uint64_t seed, double translation_mm, double rotation_deg) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  const auto direction = [&] {
    Eigen::Vector3d v(normal(rng), normal(rng), normal(rng));
    return Eigen::Vector3d(v.normalized());
  };
  const Eigen::Vector3d shift = translation_mm * direction();
  const Eigen::Quaterniond turn(
      Eigen::AngleAxisd(rotation_deg * std::numbers::pi / 180.0, direction()));
  // image points p go to c + turn (p - c) + shift before the true registration maps them.
  const Rigid3d moved(turn, centre_in_image + shift - turn * centre_in_image);
  return true_tool_from_image * moved;
}

}  // namespace tofnav
