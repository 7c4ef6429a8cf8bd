// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/fusion/tsdf_volume.hpp"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <limits>

#include "tofnav/fusion/fusion_test_scenes.hpp"
#include "tofnav/fusion/marching_cubes.hpp"
#include "tofnav/fusion/mesh_components.hpp"
#include "tofnav/fusion/mesh_test_util.hpp"

namespace tofnav {
namespace {

// A plane 301 mm ahead: the bilinear range between pixels 2.4 mm apart misses 301 / cos(theta)
// by under 0.01 mm within 20 degrees of the axis, and floats keep 0.001 mm.
constexpr double kPlaneDistanceTolMm = 0.02;
constexpr double kVoxelMm = 2.0;  // unit tests run at 2 mm to stay fast unoptimised
// Noise-free: the issue asks for a median vertex error of at most 0.1 voxel.
constexpr double kNoiseFreeMedianTolMm = 0.1 * kVoxelMm;
// Depth noise sigma 1 mm over 24 views: the bound (0.3 mm) already holds at 2 mm voxels.
constexpr double kNoisyMedianTolMm = 0.3;

const Eigen::Vector3d kSphereCentre(10.3, -5.6, 20.2);  // off the voxel grid on purpose
constexpr double kSphereRadiusMm = 60.0;
constexpr double kViewDistanceMm = 400.0;

TsdfOptions SphereOptions() {
  TsdfOptions options;
  options.voxel_size_mm = kVoxelMm;
  options.truncation_vox = 3.0;
  return options;
}

/// A 128 x 128 fisheye with the AHAT field of view (3 mm pixels at 400 mm): fast unoptimised.
const AhatCamera& SmallCamera() {
  static const AhatCamera camera(SmallFisheyeCalibration(128));
  return camera;
}

TsdfVolume FuseSphere(const TsdfOptions& options, int views, double sigma_mm = 0.0) {
  TsdfVolume volume(options, SmallCamera());
  std::mt19937_64 rng(11);
  for (const Rigid3d& pose : OrbitPoses(kSphereCentre, kViewDistanceMm, views)) {
    const Image<float> range = RenderSphere(SmallCamera(), pose, kSphereCentre, kSphereRadiusMm,
                                            sigma_mm, sigma_mm > 0.0 ? &rng : nullptr);
    EXPECT_TRUE(volume.Integrate(range, pose).integrated);
  }
  return volume;
}

TEST(TsdfOptions, CheckNamesTheBadField) {
  const auto throws = [](auto change) {
    TsdfOptions options;
    change(options);
    EXPECT_THROW(options.Check(), PreconditionError);
    EXPECT_THROW(TsdfVolume(options, SmallCamera()), PreconditionError);
  };
  throws([](TsdfOptions& o) { o.voxel_size_mm = 0.0; });
  throws([](TsdfOptions& o) { o.voxel_size_mm = std::numeric_limits<double>::quiet_NaN(); });
  throws([](TsdfOptions& o) { o.truncation_vox = -1.0; });
  throws([](TsdfOptions& o) { o.max_weight = 0.0; });
  throws([](TsdfOptions& o) { o.min_range_mm = -1.0; });
  throws([](TsdfOptions& o) { o.max_range_mm = o.min_range_mm; });
  throws([](TsdfOptions& o) { o.min_incidence_weight = 1.5; });
  throws([](TsdfOptions& o) { o.roi_in_tool = Eigen::AlignedBox3d(); });  // empty box
  EXPECT_NO_THROW(TsdfOptions{}.Check());
  TsdfMeshOptions mesh_options;
  mesh_options.min_weight = -1.0;
  EXPECT_THROW(mesh_options.Check(), PreconditionError);
}

TEST(TsdfVolume, PlaneGivesRadialSignedDistances) {
  // A 256 x 256 fisheye at the tool origin, facing a plane at z = 301 mm.
  const AhatCamera camera(SmallFisheyeCalibration(256));
  constexpr double kPlaneZMm = 301.0;
  TsdfOptions options;
  options.voxel_size_mm = kVoxelMm;
  options.truncation_vox = 3.0;
  options.roi_in_tool =
      Eigen::AlignedBox3d(Eigen::Vector3d(-8, -8, 270), Eigen::Vector3d(110, 8, 330));
  TsdfVolume volume(options, camera);
  Image<float> range(camera.width(), camera.height(), 0.0f);
  for (int v = 0; v < camera.height(); ++v) {
    for (int u = 0; u < camera.width(); ++u) {
      if (camera.IsValid(u, v))
        range(u, v) = static_cast<float>(kPlaneZMm / camera.PixelRay(u, v).z());
    }
  }
  const IntegrateResult result = volume.Integrate(range, Rigid3d::Identity());
  EXPECT_TRUE(result.integrated);
  EXPECT_GT(result.voxels_updated, 0);
  const double truncation = options.truncation_mm();
  // Along the optical axis, through the two blocks the plane's band touches (z = 288 .. 318 mm):
  // truncated in front, exact within the band, unobserved far behind.
  for (int k = 144; k < 160; ++k) {
    const double z = k * kVoxelMm;
    const std::optional<TsdfVoxel> voxel = volume.Voxel({0, 0, k});
    if (kPlaneZMm - z < -truncation) {
      EXPECT_FALSE(voxel.has_value()) << "behind the surface, z = " << z;
      continue;
    }
    ASSERT_TRUE(voxel.has_value()) << z;
    EXPECT_NEAR(voxel->distance_mm, std::min(kPlaneZMm - z, truncation), kPlaneDistanceTolMm) << z;
    EXPECT_EQ(voxel->weight, 1.0);
  }
  EXPECT_FALSE(volume.Voxel({0, 0, 140}).has_value());  // a block no point came near
  // Off axis the distance is along the ray (range - |p|), larger than the z difference.
  const Eigen::Vector3d p(100.0, 0.0, 296.0);
  const std::optional<TsdfVoxel> off_axis = volume.Voxel({50, 0, 148});
  ASSERT_TRUE(off_axis.has_value());
  EXPECT_NEAR(off_axis->distance_mm, p.norm() * (kPlaneZMm / p.z() - 1.0), kPlaneDistanceTolMm);
  EXPECT_GT(off_axis->distance_mm, kPlaneZMm - p.z() + 0.2);
}

TEST(TsdfVolume, SkipsAndCountsFramesWithoutPose) {
  TsdfVolume volume(SphereOptions(), SmallCamera());
  const Image<float> range(SmallCamera().width(), SmallCamera().height(), 400.0f);
  const IntegrateResult result = volume.Integrate(range, std::nullopt);
  EXPECT_FALSE(result.integrated);
  EXPECT_EQ(volume.frames_skipped(), 1);
  EXPECT_EQ(volume.frames_integrated(), 0);
  EXPECT_EQ(volume.block_count(), 0u);
  EXPECT_THROW(volume.Integrate(Image<float>(3, 3), Rigid3d::Identity()), PreconditionError);
}

TEST(TsdfVolume, IgnoresInvalidAndOutOfRangePixels) {
  TsdfOptions options = SphereOptions();
  options.max_range_mm = 350.0;
  TsdfVolume volume(options, SmallCamera());
  Image<float> range(SmallCamera().width(), SmallCamera().height(), 400.0f);  // beyond the max
  range(10, 10) = std::numeric_limits<float>::quiet_NaN();
  range(11, 10) = -5.0f;
  range(12, 10) = std::numeric_limits<float>::infinity();
  const IntegrateResult result = volume.Integrate(range, Rigid3d::Identity());
  EXPECT_TRUE(result.integrated);
  EXPECT_EQ(result.pixels_used, 0);
  EXPECT_EQ(volume.block_count(), 0u);
  // Raw codes: 0 and >= 4090 are invalid, the rest is range in mm.
  Image<std::uint16_t> codes(SmallCamera().width(), SmallCamera().height(), 4095);
  codes(64, 64) = 300;
  EXPECT_EQ(volume.Integrate(codes, Rigid3d::Identity()).pixels_used, 1);
}

TEST(TsdfVolume, SphereFromAllSidesIsAccurateClosedAndDeterministic) {
  const TsdfVolume volume = FuseSphere(SphereOptions(), 16);
  const TriangleMesh mesh = ExtractIsoSurface(volume);
  ASSERT_GT(mesh.triangles.size(), 5000u);
  EXPECT_LE(MedianSphereErrorMm(mesh, kSphereCentre, kSphereRadiusMm), kNoiseFreeMedianTolMm);
  EXPECT_EQ(LargestConnectedComponent(mesh).triangles.size(), mesh.triangles.size());
  const EdgeCounts edges = CountEdges(mesh);
  EXPECT_EQ(edges.boundary, 0);
  EXPECT_EQ(edges.non_manifold, 0);
  EXPECT_EQ(edges.misoriented, 0);
  EXPECT_EQ(CountDuplicateVertices(mesh), 0);
  // Outward: the positive (camera) side.
  int inward = 0;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3d& a = mesh.vertices[t[0]];
    inward += (mesh.vertices[t[1]] - a).cross(mesh.vertices[t[2]] - a).dot(a - kSphereCentre) < 0;
  }
  EXPECT_EQ(inward, 0);

  // The same frames again, and on one thread: the same bytes.
  EXPECT_TRUE(SameMesh(ExtractIsoSurface(FuseSphere(SphereOptions(), 16)), mesh));
  const tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
  EXPECT_TRUE(SameMesh(ExtractIsoSurface(volume), mesh));
}

TEST(TsdfVolume, NoisyDepthAveragesOut) {
  const TsdfVolume volume = FuseSphere(SphereOptions(), 24, 1.0);
  const TriangleMesh mesh = LargestConnectedComponent(ExtractIsoSurface(volume));
  EXPECT_LE(MedianSphereErrorMm(mesh, kSphereCentre, kSphereRadiusMm), kNoisyMedianTolMm);
}

TEST(TsdfVolume, RoiBoundsBlocksVoxelsAndMesh) {
  TsdfOptions options = SphereOptions();
  const Eigen::AlignedBox3d roi(kSphereCentre + Eigen::Vector3d(-70, -70, 0),
                                kSphereCentre + Eigen::Vector3d(70, 70, 70));
  options.roi_in_tool = roi;
  const TsdfVolume volume = FuseSphere(options, 8);
  ASSERT_GT(volume.block_count(), 0u);
  const double block_mm = kTsdfBlockSide * kVoxelMm;
  for (const Eigen::Vector3i& key : volume.block_keys()) {
    const Eigen::AlignedBox3d box(block_mm * key.cast<double>(),
                                  block_mm * (key + Eigen::Vector3i::Ones()).cast<double>());
    EXPECT_TRUE(box.intersects(roi));
  }
  const TriangleMesh mesh = ExtractIsoSurface(volume);
  ASSERT_FALSE(mesh.vertices.empty());
  for (const Eigen::Vector3d& v : mesh.vertices) EXPECT_TRUE(roi.contains(v)) << v.transpose();
}

TEST(TsdfVolume, WeightsFollowIncidenceExternalWeightsAndCap) {
  // A plane tilted 60 degrees about y, 300 mm ahead on the optical axis.
  const AhatCamera& camera = SmallCamera();
  const Eigen::Vector3d normal(std::sin(1.0472), 0.0, -std::cos(1.0472));
  Image<float> range(camera.width(), camera.height(), 0.0f);
  for (int v = 0; v < camera.height(); ++v) {
    for (int u = 0; u < camera.width(); ++u) {
      const Eigen::Vector3d ray = camera.PixelRay(u, v).cast<double>();
      const double t = 300.0 * normal.z() / ray.dot(normal);
      if (camera.IsValid(u, v) && t > 0.0 && t < 400.0) range(u, v) = static_cast<float>(t);
    }
  }
  const Eigen::Vector3i on_axis(0, 0, 150);  // z = 300 mm, on the plane
  TsdfOptions options = SphereOptions();
  options.weighting = TsdfWeighting::kIncidence;
  TsdfVolume tilted(options, camera);
  tilted.Integrate(range, Rigid3d::Identity());
  ASSERT_TRUE(tilted.Voxel(on_axis).has_value());
  // cos(60 degrees), seen by the nearest pixel's ray (up to 0.5 px = 0.016 rad off axis)
  EXPECT_NEAR(tilted.Voxel(on_axis)->weight, 0.5, 0.02);

  options.weighting = TsdfWeighting::kConstant;
  options.max_weight = 1.0;
  TsdfVolume capped(options, camera);
  const Image<float> quarter(camera.width(), camera.height(), 0.25f);
  for (int i = 0; i < 3; ++i) capped.Integrate(range, Rigid3d::Identity(), quarter);
  EXPECT_NEAR(capped.Voxel(on_axis)->weight, 0.75, 1e-6);
  for (int i = 0; i < 3; ++i) capped.Integrate(range, Rigid3d::Identity(), quarter);
  EXPECT_NEAR(capped.Voxel(on_axis)->weight, 1.0, 1e-6);  // capped
  const IntegrateResult none =
      capped.Integrate(range, Rigid3d::Identity(), Image<float>(camera.width(), camera.height()));
  EXPECT_EQ(none.voxels_updated, 0);  // zero weights update nothing
}

TEST(TsdfVolume, MinWeightDropsRarelySeenSurface) {
  const TsdfVolume volume = FuseSphere(SphereOptions(), 4);
  TsdfMeshOptions options;
  EXPECT_FALSE(ExtractIsoSurface(volume, options).triangles.empty());
  options.min_weight = 4.0;  // more than four frames could give
  EXPECT_TRUE(ExtractIsoSurface(volume, options).triangles.empty());
}

}  // namespace
}  // namespace tofnav
