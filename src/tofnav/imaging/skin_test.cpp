// SPDX-License-Identifier: BSD-3-Clause
// Skin extraction on a synthetic head: a sphere with a sinus, an airway and a head holder.
#include "tofnav/imaging/skin.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "tofnav/core/require.hpp"

namespace tofnav {
namespace {

constexpr double kHeadRadiusMm = 45.0;
constexpr double kEdgeWidthMm = 4.0;  // partial-volume ramp of the air/skin edge
constexpr double kTissueHu = 40.0, kAirHu = -1000.0, kHolderHu = 300.0;
/// The -300 HU crossing of the linear ramp, inside the nominal radius.
constexpr double kIsoRadiusMm =
    kHeadRadiusMm + ((kTissueHu - kCtSkinThresholdHu) / (kTissueHu - kAirHu) - 0.5) * kEdgeWidthMm;
/// Marching cubes interpolates linearly along voxel edges; the ramp is linear in the distance but
/// the sphere is curved over a 2.5 mm edge: chord error r (1 - cos) well under this.
constexpr double kSurfaceToleranceMm = 0.25;

double Ramp(double distance_outside_mm) {
  const double f = std::clamp(distance_outside_mm / kEdgeWidthMm + 0.5, 0.0, 1.0);
  return kTissueHu + f * (kAirHu - kTissueHu);
}

/// 2 x 2 x 2.5 mm voxels over about 120 x 120 x 120 mm, centred on the head (built once).
const CtVolume& SyntheticHeadCt() {
  static const CtVolume head = [] {
    CtVolume volume;
    volume.dims = {60, 60, 48};
    volume.modality = "CT";
    volume.image_from_ijk.diagonal() << 2.0, 2.0, 2.5, 1.0;
    volume.image_from_ijk.topRightCorner<3, 1>() = Eigen::Vector3d(-59.0, -59.0, -58.75);
    volume.values.resize(volume.voxel_count());
    for (int k = 0; k < volume.nz(); ++k) {
      for (int j = 0; j < volume.ny(); ++j) {
        for (int i = 0; i < volume.nx(); ++i) {
          const Eigen::Vector3d p(-59.0 + 2.0 * i, -59.0 + 2.0 * j, -58.75 + 2.5 * k);
          double hu = Ramp(p.norm() - kHeadRadiusMm);
          if ((p - Eigen::Vector3d(0, 15, 0)).norm() < 8.0) hu = kAirHu;  // a sinus
          if (p.head<2>().norm() < 5.0 && p.z() < -20.0) hu = kAirHu;     // an airway, open below
          if (p.z() > -58.0 && p.z() < -52.0 && p.head<2>().norm() < 50.0) hu = kHolderHu;
          volume.values[volume.Index(i, j, k)] = static_cast<float>(hu);
        }
      }
    }
    return volume;
  }();
  return head;
}

CtVolume SyntheticHead(const std::string& modality = "CT") {
  CtVolume volume = SyntheticHeadCt();
  volume.modality = modality;
  return volume;
}

/// ExtractSkin of the CT with the default options (computed once).
const SkinResult& DefaultSkin() {
  static const SkinResult skin = ExtractSkin(SyntheticHead());
  return skin;
}

/// Over the vertices above `above_z_mm` (all by default).
double MaxRadiusError(const TriangleMesh& mesh, double radius_mm, double above_z_mm = -1e9) {
  double worst = 0.0;
  for (const Eigen::Vector3d& p : mesh.vertices) {
    if (p.z() >= above_z_mm) worst = std::max(worst, std::abs(p.norm() - radius_mm));
  }
  return worst;
}

TEST(ExtractSkin, OuterSurfaceOnlyWithOutwardNormals) {
  const SkinResult& skin = DefaultSkin();
  EXPECT_EQ(skin.threshold, kCtSkinThresholdHu);
  EXPECT_EQ(skin.threshold_source, "CT default");
  EXPECT_EQ(skin.mask_components, 2);  // head and holder
  EXPECT_GT(skin.filled_voxels, 0U);   // sinus and airway
  ASSERT_GT(skin.mesh.vertices.size(), 1000U);
  // Away from the airway's mouth (z < -40 mm), the sphere; the mouth is capped flat where its
  // fill ends, within one 2.5 mm slice of the sphere.
  EXPECT_LT(MaxRadiusError(skin.mesh, kIsoRadiusMm, -40.0), kSurfaceToleranceMm);
  EXPECT_LT(MaxRadiusError(skin.mesh, kIsoRadiusMm), 1.0);
  ASSERT_EQ(skin.mesh.vertex_normals.size(), skin.mesh.vertices.size());
  double min_cosine = 1.0;
  for (std::size_t v = 0; v < skin.mesh.vertices.size(); ++v) {
    min_cosine =
        std::min(min_cosine, skin.mesh.vertex_normals[v].dot(skin.mesh.vertices[v].normalized()));
  }
  EXPECT_GT(min_cosine, 0.9);  // outward everywhere (facets of a 2.5 mm grid on a sphere)
}

TEST(ExtractSkin, WithoutFillTheSinusAndAirwayAreMeshed) {
  SkinOptions options;
  options.fill_cavities = false;
  const SkinResult skin = ExtractSkin(SyntheticHead(), options);
  EXPECT_GT(MaxRadiusError(skin.mesh, kIsoRadiusMm), 10.0);  // the airway wall, 5 mm off axis
  options.keep_largest_component = false;
  options.fill_cavities = true;
  const SkinResult with_holder = ExtractSkin(SyntheticHead(), options);
  EXPECT_GT(with_holder.dropped_triangles, 0U);  // the holder is meshed, then dropped as smaller
}

TEST(ExtractSkin, SmoothingKeepsTheRadiusAndDecimationThins) {
  const SkinResult& plain = DefaultSkin();
  SkinOptions options;
  options.smoothing_iterations = 10;
  options.decimation_cell_mm = 5.0;
  const SkinResult thin = ExtractSkin(SyntheticHead(), options);
  EXPECT_LT(thin.mesh.vertices.size() * 3, plain.mesh.vertices.size());
  // Taubin does not shrink; cluster means lie on chords of a 45 mm sphere within 5 mm cells.
  constexpr double kDecimatedToleranceMm = 0.4;
  EXPECT_LT(MaxRadiusError(thin.mesh, kIsoRadiusMm, -40.0), kDecimatedToleranceMm);
  EXPECT_EQ(thin.mesh.vertex_normals.size(), thin.mesh.vertices.size());
  thin.mesh.CheckConsistent();
}

TEST(ExtractSkin, MrUsesOtsuAndRasFlipsXy) {
  CtVolume volume = SyntheticHead("MR");
  for (float& v : volume.values) v = (v - static_cast<float>(kAirHu)) / 10.0f;  // 0 .. ~130
  const SkinResult skin = ExtractSkin(volume);
  EXPECT_EQ(skin.threshold_source, "Otsu");
  EXPECT_GT(skin.threshold, 10.0);
  EXPECT_LT(skin.threshold, 100.0);
  // Wherever Otsu lands, the surface lies within the partial-volume ramp.
  EXPECT_LT(MaxRadiusError(skin.mesh, kHeadRadiusMm, -40.0),
            kEdgeWidthMm / 2 + kSurfaceToleranceMm);
  const TriangleMesh ras = MeshLpsToRas(skin.mesh);
  EXPECT_EQ(ras.vertices[0], Eigen::Vector3d(-skin.mesh.vertices[0].x(), -skin.mesh.vertices[0].y(),
                                             skin.mesh.vertices[0].z()));
  EXPECT_EQ(ras.triangles, skin.mesh.triangles);
}

TEST(OtsuThreshold, SplitsTwoModes) {
  std::mt19937 rng(7);
  std::normal_distribution<float> low(10.0f, 2.0f), high(90.0f, 5.0f);
  std::vector<float> values;
  for (int i = 0; i < 4000; ++i) values.push_back(i % 3 == 0 ? high(rng) : low(rng));
  const double t = OtsuThreshold(values);
  EXPECT_GT(t, 40.0);  // the middle of the empty gap between about 18 and 75
  EXPECT_LT(t, 55.0);
  EXPECT_THROW(OtsuThreshold(std::vector<float>(10, 1.0f)), PreconditionError);
}

TEST(ExtractSkin, EmptyMaskAndBadOptionsAreErrors) {
  CtVolume air = SyntheticHead();
  std::fill(air.values.begin(), air.values.end(), static_cast<float>(kAirHu));
  EXPECT_THROW(ExtractSkin(air), PreconditionError);
  SkinOptions bad;
  bad.decimation_cell_mm = -1.0;
  EXPECT_THROW(ExtractSkin(SyntheticHead(), bad), PreconditionError);
  bad = SkinOptions{};
  bad.opening_radius_mm = -1.0;
  EXPECT_THROW(ExtractSkin(SyntheticHead(), bad), PreconditionError);
}

TEST(ExtractSkin, VolumesWithoutSkinAreClearErrors) {
  // Every one a PreconditionError (the CLI names the file), never an internal error.
  CtVolume zeros = SyntheticHead("MR");
  std::fill(zeros.values.begin(), zeros.values.end(), 0.0f);  // an empty MR: Otsu has no split
  EXPECT_THROW(ExtractSkin(zeros), PreconditionError);
  CtVolume nans = zeros;
  std::fill(nans.values.begin(), nans.values.end(), std::nanf(""));
  EXPECT_THROW(ExtractSkin(nans), PreconditionError);
  CtVolume tissue = SyntheticHead();  // the mask fills the field of view: no boundary
  std::fill(tissue.values.begin(), tissue.values.end(), static_cast<float>(kTissueHu));
  EXPECT_THROW(ExtractSkin(tissue), PreconditionError);
  CtVolume slice = SyntheticHead();  // one axial slice: no cell to mesh
  slice.dims[2] = 1;
  slice.values.resize(slice.voxel_count());
  EXPECT_THROW(ExtractSkin(slice), PreconditionError);
  SkinOptions above_everything;
  above_everything.threshold = 5000.0;
  EXPECT_THROW(ExtractSkin(SyntheticHead(), above_everything), PreconditionError);
}

}  // namespace
}  // namespace tofnav
