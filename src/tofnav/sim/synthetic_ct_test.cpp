// SPDX-License-Identifier: BSD-3-Clause
// Synthetic CT of a sphere "head": exact volume, HU layers by depth, ventricles, noise.
#include "tofnav/sim/synthetic_ct.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "tofnav/core/require.hpp"
#include "tofnav/sim/shapes.hpp"

namespace tofnav::sim {
namespace {

constexpr double kRadiusMm = 40.0;
constexpr double kSpacingMm = 2.0;

struct Sampler {
  const SyntheticCt& ct;
  // Value of the voxel whose centre is nearest to p.
  double operator()(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d ijk = (p - ct.image_from_ijk.topRightCorner<3, 1>()) / kSpacingMm;
    const auto i = static_cast<std::size_t>(std::lround(ijk.x()));
    const auto j = static_cast<std::size_t>(std::lround(ijk.y()));
    const auto k = static_cast<std::size_t>(std::lround(ijk.z()));
    const auto nx = static_cast<std::size_t>(ct.dims[0]), ny = static_cast<std::size_t>(ct.dims[1]);
    return ct.values_hu[i + nx * (j + ny * k)];
  }
};

SyntheticCtOptions NoiseFree() {
  SyntheticCtOptions options;
  options.spacing_mm = kSpacingMm;
  options.noise_sigma_hu = 0.0;
  return options;
}

HeadAnatomy SphereAnatomy() {
  HeadAnatomy anatomy;
  anatomy.centre_in_image = {3.0, -4.0, 5.0};
  anatomy.semi_axes_mm = Eigen::Vector3d::Constant(kRadiusMm);
  return anatomy;
}

TriangleMesh SphereHead() {
  return Transform(Rigid3d(Eigen::Quaterniond::Identity(), SphereAnatomy().centre_in_image),
                   SphereMesh(kRadiusMm, 64));
}

TEST(SynthesizeHeadCt, PartialVolumeAddsUpToTheMeshVolume) {
  // One tissue value everywhere, so a voxel's value is air + f (tissue - air) exactly.
  SyntheticCtOptions o = NoiseFree();
  o.soft_tissue_hu = o.skull_table_hu = o.skull_diploe_hu = o.brain_hu = o.ventricle_hu = 0.0;
  const SyntheticCt ct = SynthesizeHeadCt(SphereHead(), SphereAnatomy(), o, 1);
  double inside_voxels = 0.0;
  for (const float hu : ct.values_hu) inside_voxels += (hu - o.air_hu) / (0.0 - o.air_hu);
  // The 64-segment mesh is smaller than the sphere by its chord sag; compare with the mesh
  // volume bounds: the inscribed polyhedron lies between r cos(pi/64) and r.
  const double volume_mm3 = inside_voxels * std::pow(kSpacingMm, 3);
  const double outer = 4.0 / 3.0 * std::numbers::pi * std::pow(kRadiusMm, 3);
  const double inner = outer * std::pow(std::cos(std::numbers::pi / 64.0), 3);
  EXPECT_GT(volume_mm3, inner * 0.995);
  EXPECT_LT(volume_mm3, outer * 1.005);
  EXPECT_EQ(ct.image_from_ijk(0, 0), kSpacingMm);
  EXPECT_EQ(ct.values_hu.size(), static_cast<std::size_t>(ct.dims[0]) *
                                     static_cast<std::size_t>(ct.dims[1]) *
                                     static_cast<std::size_t>(ct.dims[2]));
}

TEST(SynthesizeHeadCt, LayersFollowTheDepthBelowTheSkin) {
  const SyntheticCtOptions o = NoiseFree();
  const SyntheticCt ct = SynthesizeHeadCt(SphereHead(), SphereAnatomy(), o, 1);
  const Sampler at{ct};
  const Eigen::Vector3d c = SphereAnatomy().centre_in_image;
  const Eigen::Vector3d down = -Eigen::Vector3d::UnitZ();  // away from the ventricles
  constexpr double kEdgeTolHu = 1.0;  // no noise; well inside a layer the value is exact
  EXPECT_NEAR(at(c + down * (kRadiusMm + 8.0)), o.air_hu, kEdgeTolHu);
  EXPECT_NEAR(at(c + down * (kRadiusMm - 3.0)), o.soft_tissue_hu, kEdgeTolHu);
  EXPECT_GE(at(c + down * (kRadiusMm - o.scalp_mm - 0.5 * o.skull_mm)),
            o.skull_diploe_hu - kEdgeTolHu);
  EXPECT_NEAR(at(c + down * (kRadiusMm - 25.0)), o.brain_hu, kEdgeTolHu);
  const Ellipsoid ventricle = SphereAnatomy().Ventricles()[0];
  EXPECT_NEAR(at(ventricle.centre_in_image), o.ventricle_hu, kEdgeTolHu);
  EXPECT_LT(ventricle.centre_in_image.x(), c.x());  // LPS: the first ventricle is the right one
}

TEST(SynthesizeHeadCt, NoiseIsSeededWithTheRequestedSpread) {
  SyntheticCtOptions o = NoiseFree();
  o.noise_sigma_hu = 20.0;
  o.spacing_mm = 4.0;
  const SyntheticCt a = SynthesizeHeadCt(SphereHead(), SphereAnatomy(), o, 1);
  const SyntheticCt b = SynthesizeHeadCt(SphereHead(), SphereAnatomy(), o, 1);
  const SyntheticCt c = SynthesizeHeadCt(SphereHead(), SphereAnatomy(), o, 2);
  EXPECT_EQ(a.values_hu, b.values_hu);
  EXPECT_NE(a.values_hu, c.values_hu);
  // Air voxels of the first slice: mean -1000, spread 20 HU (thousands of samples: +-5 %).
  double sum = 0.0, sum2 = 0.0;
  const std::size_t n = static_cast<std::size_t>(a.dims[0]) * static_cast<std::size_t>(a.dims[1]);
  for (std::size_t i = 0; i < n; ++i) {
    sum += a.values_hu[i] - o.air_hu;
    sum2 += std::pow(a.values_hu[i] - o.air_hu, 2);
  }
  EXPECT_NEAR(sum / static_cast<double>(n), 0.0, 2.0);
  EXPECT_NEAR(std::sqrt(sum2 / static_cast<double>(n)), 20.0, 1.0);
}

TEST(SynthesizeHeadCt, RejectsBadOptions) {
  SyntheticCtOptions o;
  o.spacing_mm = 0.0;
  EXPECT_THROW(SynthesizeHeadCt(SphereHead(), SphereAnatomy(), o, 1), PreconditionError);
  EXPECT_THROW(SynthesizeHeadCt(TriangleMesh{}, SphereAnatomy(), NoiseFree(), 1),
               PreconditionError);
}

}  // namespace
}  // namespace tofnav::sim
