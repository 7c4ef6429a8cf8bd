// SPDX-License-Identifier: BSD-3-Clause
// EVD plan: Kocher's point by walking the midline scalp from the nasion, targets in the ventricles.
#include "tofnav/sim/evd_plan.hpp"

#include <cmath>
#include <numbers>

#include "tofnav/core/require.hpp"
#include "tofnav/sim/mesh_probe.hpp"

namespace tofnav::sim {
namespace {

// Midline direction at elevation e in the sagittal plane (LPS: anterior -y, superior +z).
Eigen::Vector3d MidlineDirection(double elevation_rad) {
  return {0.0, -std::cos(elevation_rad), std::sin(elevation_rad)};
}

// The midline scalp point `arc_mm` along the surface, posterior-superior from the nasion.
Eigen::Vector3d MidlineArcPoint(const MeshProbe& skin, const HeadAnatomy& anatomy, double arc_mm) {
  constexpr double kStepRad = 0.01;  // about 1 mm chords on a head
  double elevation = anatomy.nasion_elevation_rad;
  Eigen::Vector3d previous = skin.RequireHit(MidlineDirection(elevation), "the nasion").point;
  double walked_mm = 0.0;
  while (elevation < std::numbers::pi) {
    elevation += kStepRad;
    const Eigen::Vector3d next =
        skin.RequireHit(MidlineDirection(elevation), "the midline scalp").point;
    const double step_mm = (next - previous).norm();
    if (walked_mm + step_mm >= arc_mm) {
      return previous + (arc_mm - walked_mm) / step_mm * (next - previous);
    }
    walked_mm += step_mm;
    previous = next;
  }
  Require(false, "PlanEvdTrajectories: the midline scalp is shorter than kocher_arc_mm");
  return previous;
}

// Skin point seen from the anatomy centre towards `point` (projects a point onto the scalp).
Eigen::Vector3d OnSkin(const MeshProbe& skin, const Eigen::Vector3d& point) {
  return skin.RequireHit(point - skin.origin(), "an EVD entry point").point;
}

}  // namespace

void EvdPlanOptions::Check() const {
  Require(kocher_arc_mm > 0.0 && kocher_lateral_mm >= 0.0 && top_posterior_mm >= 0.0 &&
              entry_spread_mm >= 0.0,
          "EvdPlanOptions: distances must be >= 0 (kocher_arc_mm > 0)");
}

std::vector<Trajectory> PlanEvdTrajectories(const TriangleMesh& skin_in_image,
                                            const HeadAnatomy& anatomy,
                                            const EvdPlanOptions& options) {
  return PlanEvdTrajectories(MeshProbe(skin_in_image, anatomy.centre_in_image), anatomy, options);
}

std::vector<Trajectory> PlanEvdTrajectories(const MeshProbe& skin, const HeadAnatomy& anatomy,
                                            const EvdPlanOptions& options) {
  options.Check();
  Require(skin.origin() == anatomy.centre_in_image,
          "PlanEvdTrajectories: the probe must cast from the anatomy centre");
  const Eigen::Vector3d kocher_mid = MidlineArcPoint(skin, anatomy, options.kocher_arc_mm);
  const Eigen::Vector3d lateral = Eigen::Vector3d::UnitX();    // LPS: +x is left
  const Eigen::Vector3d posterior = Eigen::Vector3d::UnitY();  // LPS: +y is posterior
  const double s = options.entry_spread_mm;
  const std::array<Ellipsoid, 2> ventricles = anatomy.Ventricles();  // right, left

  // Targets of one side: frontal horn tip, frontal horn body, foramen of Monro (medial, low).
  const auto side_targets = [&](int side) {
    const Ellipsoid& v = ventricles[static_cast<std::size_t>(side)];
    const Eigen::Vector3d& a = v.semi_axes_mm;
    const double medial = side == 0 ? 1.0 : -1.0;  // towards the midline
    return std::array<Eigen::Vector3d, 3>{
        v.centre_in_image + Eigen::Vector3d(0.0, -0.85 * a.y(), 0.0),
        v.centre_in_image + Eigen::Vector3d(0.0, -0.5 * a.y(), -0.2 * a.z()),
        v.centre_in_image + Eigen::Vector3d(medial * 0.6 * a.x(), -0.1 * a.y(), -0.5 * a.z())};
  };
  std::vector<Trajectory> plan;
  const char* names[2] = {"right", "left"};
  for (int side = 0; side < 2; ++side) {
    const double sign = side == 0 ? -1.0 : 1.0;
    const Eigen::Vector3d hole = kocher_mid + sign * options.kocher_lateral_mm * lateral;
    const std::array<Eigen::Vector3d, 3> offsets = {Eigen::Vector3d::Zero(),
                                                    Eigen::Vector3d(-s * posterior),
                                                    Eigen::Vector3d(sign * s * lateral)};
    const std::array<Eigen::Vector3d, 3> targets = side_targets(side);
    for (std::size_t n = 0; n < 3; ++n) {
      plan.push_back({std::string(names[side]) + "-" + std::to_string(n + 1),
                      OnSkin(skin, hole + offsets[n]), targets[n]});
    }
  }
  const Eigen::Vector3d top = kocher_mid + options.top_posterior_mm * posterior;
  const std::array<Eigen::Vector3d, 3> right = side_targets(0), left = side_targets(1);
  const std::array<Eigen::Vector3d, 3> top_targets = {right[0], left[0], right[2]};
  const std::array<Eigen::Vector3d, 3> top_offsets = {
      Eigen::Vector3d(-s * lateral), Eigen::Vector3d(s * lateral), Eigen::Vector3d(s * posterior)};
  for (std::size_t n = 0; n < 3; ++n) {
    plan.push_back(
        {"top-" + std::to_string(n + 1), OnSkin(skin, top + top_offsets[n]), top_targets[n]});
  }
  return plan;
}

}  // namespace tofnav::sim
