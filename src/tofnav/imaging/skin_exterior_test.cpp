// SPDX-License-Identifier: BSD-3-Clause
// The outer surface only: a synthetic head with a cavity reached through a narrow canal, whole
// and cropped through the cavity (docs/registration.md 1.).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "tofnav/imaging/skin.hpp"

namespace tofnav {
namespace {

constexpr int kSide = 64;
constexpr double kVoxelMm = 1.5;
constexpr double kHeadRadiusMm = 40.0, kCavityRadiusMm = 12.0, kCanalRadiusMm = 2.5;
constexpr double kEdgeWidthMm = 3.0;  // partial-volume ramp of every air/tissue edge
constexpr double kTissueHu = 40.0, kAirHu = -1000.0;
/// The -300 HU crossing of the linear ramp, inside the nominal radius.
constexpr double kIsoRadiusMm =
    kHeadRadiusMm + ((kTissueHu - kCtSkinThresholdHu) / (kTissueHu - kAirHu) - 0.5) * kEdgeWidthMm;
/// Marching cubes of the smooth ramp on a 1.5 mm grid: measured within 0.05 % of the sphere's
/// area (whole and cut); the capped 2.5 mm canal mouth is 0.01 %. 1 % leaves room for both and
/// still catches the inner walls it guards against: the cavity alone adds 9 % ((12 / 39)^2).
constexpr double kAreaRelTol = 0.01;
/// Vertices interpolate a linear ramp along 1.5 mm edges: chord error r (1 - cos) is ~0.03 mm;
/// near the capped mouth and the cut they sit within a voxel of the sphere.
constexpr double kRadiusTolMm = kVoxelMm;

double Centre(int i) { return kVoxelMm * (i - 0.5 * (kSide - 1)); }

/// A CT head: a 40 mm ball with a 12 mm air cavity at its centre, reached from +x through a
/// 2.5 mm canal in the axial plane (no axial slice encloses it: only the ball fill closes it).
CtVolume HeadWithCanal() {
  CtVolume volume;
  volume.dims = {kSide, kSide, kSide};
  volume.modality = "CT";
  volume.image_from_ijk.diagonal() << kVoxelMm, kVoxelMm, kVoxelMm, 1.0;
  volume.image_from_ijk.topRightCorner<3, 1>() = Eigen::Vector3d::Constant(Centre(0));
  volume.values.resize(volume.voxel_count());
  for (int k = 0; k < kSide; ++k) {
    for (int j = 0; j < kSide; ++j) {
      for (int i = 0; i < kSide; ++i) {
        const Eigen::Vector3d p(Centre(i), Centre(j), Centre(k));
        double outside_mm = p.norm() - kHeadRadiusMm;  // signed distance to the air
        outside_mm = std::max(outside_mm, kCavityRadiusMm - p.norm());
        if (p.x() > 0.0) outside_mm = std::max(outside_mm, kCanalRadiusMm - p.tail<2>().norm());
        const double f = std::clamp(outside_mm / kEdgeWidthMm + 0.5, 0.0, 1.0);
        volume.values[volume.Index(i, j, k)] =
            static_cast<float>(kTissueHu + f * (kAirHu - kTissueHu));
      }
    }
  }
  return volume;
}

double MinRadius(const TriangleMesh& mesh) {
  double lowest = 1e9;
  for (const Eigen::Vector3d& p : mesh.vertices) lowest = std::min(lowest, p.norm());
  return lowest;
}

TEST(ExtractSkinOpenings, CavityBehindANarrowCanalIsNotMeshed) {
  const SkinResult skin = ExtractSkin(HeadWithCanal());
  const double sphere = 4.0 * std::numbers::pi * kIsoRadiusMm * kIsoRadiusMm;
  EXPECT_NEAR(skin.mesh.SurfaceAreaMm2(), sphere, kAreaRelTol * sphere);
  EXPECT_GT(MinRadius(skin.mesh), kIsoRadiusMm - kRadiusTolMm);
  // Without the ball the canal and the cavity are open to the outside and meshed.
  SkinOptions no_ball;
  no_ball.opening_radius_mm = 0.0;
  const SkinResult open = ExtractSkin(HeadWithCanal(), no_ball);
  EXPECT_GT(open.mesh.SurfaceAreaMm2(),
            sphere + 0.8 * 4.0 * std::numbers::pi * kCavityRadiusMm * kCavityRadiusMm);
  EXPECT_LT(MinRadius(open.mesh), kCavityRadiusMm + kRadiusTolMm);
  // A ball narrower than the canal enters it: the cavity is outside, as it would be to a camera.
  SkinOptions thin_ball;
  thin_ball.opening_radius_mm = 1.0;
  EXPECT_LT(MinRadius(ExtractSkin(HeadWithCanal(), thin_ball).mesh),
            kCavityRadiusMm + kRadiusTolMm);
}

TEST(ExtractSkinOpenings, CropThroughTheCavityKeepsOnlyTheOuterSurface) {
  // The field of view ends at x = 6 mm, inside the cavity: on the cut face the cavity is air
  // enclosed by tissue, not outside air, and the surface is left open at the cut.
  constexpr int kKeep = 37;
  const CtVolume crop = CropVolume(HeadWithCanal(), {0, 0, 0}, {kKeep, kSide, kSide});
  const SkinResult skin = ExtractSkin(crop);
  const double last_x = Centre(kKeep - 1);
  const double zone = 2.0 * std::numbers::pi * kIsoRadiusMm * (kIsoRadiusMm + last_x);
  EXPECT_NEAR(skin.mesh.SurfaceAreaMm2(), zone, kAreaRelTol * zone);
  EXPECT_GT(MinRadius(skin.mesh), kIsoRadiusMm - kRadiusTolMm);
  for (const Eigen::Vector3d& p : skin.mesh.vertices) EXPECT_LE(p.x(), last_x + 1e-9);
}

}  // namespace
}  // namespace tofnav
