// SPDX-License-Identifier: BSD-3-Clause
// Embree ray casting: exact ranges and normals, occlusion, ids, and pose updates.
#include "tofnav/sim/raycaster.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "tofnav/sim/shapes.hpp"
#include "tofnav/sim/sim_test_scenes.hpp"

namespace tofnav::sim {
namespace {

using testing::FacingPose;

constexpr double kRangeTolMm = 1e-9;  // double-precision refinement on the exact primitive
constexpr double kNormalTol = 1e-9;

std::vector<RayHit> Cast(const SceneRaycaster& raycaster,
                         const std::vector<Eigen::Vector3d>& rays) {
  std::vector<RayHit> hits(rays.size());
  raycaster.Intersect(rays, hits);
  return hits;
}

TEST(SceneRaycaster, HitsABoardAtItsExactRange) {
  const Scene scene = testing::BoardScene(DiffuseMaterial(0.5), 500.0);
  const SceneRaycaster raycaster(scene);
  std::vector<Eigen::Vector3d> rays;
  for (int k = 0; k < 50; ++k)
    rays.push_back(Eigen::Vector3d(0.013 * k, -0.007 * k, 1.0).normalized());
  const std::vector<RayHit> hits = Cast(raycaster, rays);
  for (std::size_t k = 0; k < rays.size(); ++k) {
    ASSERT_TRUE(hits[k].hit());
    EXPECT_NEAR(hits[k].range_mm, 500.0 / rays[k].z(), kRangeTolMm);
    EXPECT_NEAR((hits[k].normal_in_ahat - Eigen::Vector3d(0, 0, -1)).norm(), 0.0, kNormalTol);
    EXPECT_EQ(hits[k].object, 0);
    EXPECT_EQ(hits[k].material, 0);
    EXPECT_EQ(hits[k].marker, -1);
  }
  EXPECT_FALSE(Cast(raycaster, {Eigen::Vector3d(0, 0, -1)})[0].hit());  // behind the camera
}

TEST(SceneRaycaster, HitsSphereAndDiscMarkersExactlyAndInFrontOfTheBoard) {
  Scene scene = testing::BoardScene(DiffuseMaterial(0.5), 500.0);
  const int retro = scene.AddMaterial(RetroReflectiveMaterial());
  Tool tool;
  tool.markers.push_back(SphereMarker({0.0, 0.0, 0.0}, 10.0, retro));
  tool.markers.push_back(
      DiscMarkerOnSurface({60.0, 0.0, 100.0}, {0.0, 0.0, -1.0}, 10.0, retro, 0.1));
  tool.scene_from_tool = Rigid3d(Eigen::Quaterniond::Identity(), {0.0, 0.0, 300.0});
  scene.AddTool(tool);
  const SceneRaycaster raycaster(scene);
  // Through the sphere centre, and 3 mm off it at 300 mm.
  const Eigen::Vector3d off = Eigen::Vector3d(3.0, 0.0, 300.0).normalized();
  const Eigen::Vector3d disc = Eigen::Vector3d(60.0, 0.0, 399.9).normalized();
  const Eigen::Vector3d beside = Eigen::Vector3d(66.0, 0.0, 399.9).normalized();
  const std::vector<RayHit> hits = Cast(raycaster, {Eigen::Vector3d::UnitZ(), off, disc, beside});
  EXPECT_NEAR(hits[0].range_mm, 295.0, kRangeTolMm);
  EXPECT_NEAR((hits[0].normal_in_ahat + Eigen::Vector3d::UnitZ()).norm(), 0.0, kNormalTol);
  EXPECT_EQ(hits[0].tool, 0);
  EXPECT_EQ(hits[0].marker, 0);
  EXPECT_EQ(hits[0].object, -1);
  EXPECT_EQ(hits[0].material, retro);
  const Eigen::Vector3d c(0.0, 0.0, 300.0);  // ray-sphere intersection, nearest root
  const double b = off.dot(c), t = b - std::sqrt(b * b - c.squaredNorm() + 25.0);
  EXPECT_NEAR(hits[1].range_mm, t, kRangeTolMm);
  EXPECT_NEAR((hits[1].normal_in_ahat - (t * off - c) / 5.0).norm(), 0.0, kNormalTol);
  EXPECT_EQ(hits[2].marker, 1);
  EXPECT_NEAR(hits[2].range_mm, (Eigen::Vector3d(60.0, 0.0, 399.9)).norm(), kRangeTolMm);
  EXPECT_EQ(hits[3].object, 0);  // 6 mm from the disc centre: the board behind it
  EXPECT_NEAR(hits[3].range_mm, 500.0 / beside.z(), kRangeTolMm);
}

TEST(SceneRaycaster, SetPosesMovesObjectsToolsAndTheCamera) {
  Scene scene = testing::BoardScene(DiffuseMaterial(0.5), 500.0);
  SceneRaycaster raycaster(scene);
  scene.objects[0].scene_from_object = FacingPose(650.0);
  raycaster.SetPoses(scene, Rigid3d::Identity());
  EXPECT_NEAR(Cast(raycaster, {Eigen::Vector3d::UnitZ()})[0].range_mm, 650.0, kRangeTolMm);
  // Camera 100 mm forward and turned 0.3 rad about y: the board is tilted in `ahat`.
  const Rigid3d scene_from_ahat(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY())), {0.0, 0.0, 100.0});
  raycaster.SetPoses(scene, scene_from_ahat);
  const RayHit hit = Cast(raycaster, {Eigen::Vector3d::UnitZ()})[0];
  EXPECT_NEAR(hit.range_mm, 550.0 / std::cos(0.3), kRangeTolMm);
  EXPECT_NEAR(std::acos(-hit.normal_in_ahat.z()), 0.3, kNormalTol);
}

TEST(SceneRaycaster, RejectsPosesOfAnotherScene) {
  Scene scene = testing::BoardScene(DiffuseMaterial(0.5), 500.0);
  SceneRaycaster raycaster(scene);
  scene.AddObject("extra", BoxMesh({1.0, 1.0, 1.0}), 0, Rigid3d::Identity());
  EXPECT_THROW(raycaster.SetPoses(scene, Rigid3d::Identity()), std::invalid_argument);
}

TEST(SceneRaycaster, UsesInterpolatedVertexNormalsForShading) {
  Scene scene;
  const int m = scene.AddMaterial(DiffuseMaterial(0.5));
  scene.AddObject("sphere", SphereMesh(100.0, 48), m,
                  Rigid3d(Eigen::Quaterniond::Identity(), {0, 0, 600}));
  const SceneRaycaster raycaster(scene);
  const Eigen::Vector3d ray = Eigen::Vector3d(0.1, 0.05, 1.0).normalized();
  const RayHit hit = Cast(raycaster, {ray})[0];
  const Eigen::Vector3d radial = (hit.range_mm * ray - Eigen::Vector3d(0, 0, 600)).normalized();
  EXPECT_NEAR((hit.normal_in_ahat - radial).norm(), 0.0, 0.01);  // smooth, not the facet normal
}

TEST(SceneRaycaster, DrawsAConformingStickerOnItsObjectsSurface) {
  // A 10 mm tape sticker, 0.1 mm thick, on a board 500 mm ahead that is tilted 0.4 rad about y;
  // the tool and the board share a pose (the sticker moves with its object).
  Scene scene = testing::BoardScene(DiffuseMaterial(0.5), 500.0, 0.4);
  const Rigid3d tilt = scene.objects[0].scene_from_object;
  const int retro = scene.AddMaterial(RetroReflectiveMaterial());
  Tool tool;
  Marker sticker = DiscMarkerOnSurface({0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, 10.0, retro, 0.1);
  sticker.conforms_to_object = 0;
  tool.markers.push_back(sticker);
  tool.scene_from_tool = tilt;
  scene.AddTool(tool);
  SceneRaycaster raycaster(scene);
  const Eigen::Vector3d normal = tilt.rotation * Eigen::Vector3d::UnitZ();  // towards the camera
  const auto board_range = [&](const Eigen::Vector3d& ray) {  // plane through (0, 0, 500)
    return normal.dot(Eigen::Vector3d(0.0, 0.0, 500.0)) / normal.dot(ray);
  };
  const Eigen::Vector3d centre = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d inside = Eigen::Vector3d(3.0, 1.0, 500.0).normalized();
  const Eigen::Vector3d outside = Eigen::Vector3d(0.0, 6.0, 500.0).normalized();
  const std::vector<RayHit> hits = Cast(raycaster, {centre, inside, outside});
  for (int k : {0, 1}) {
    const Eigen::Vector3d& ray = k == 0 ? centre : inside;
    EXPECT_EQ(hits[k].tool, 0);
    EXPECT_EQ(hits[k].marker, 0);
    EXPECT_EQ(hits[k].object, -1);
    EXPECT_EQ(hits[k].material, retro);
    // The tape's front face: 0.1 mm along the normal, 0.1 / cos(incidence) along the ray.
    EXPECT_NEAR(hits[k].range_mm, board_range(ray) - 0.1 / std::abs(normal.dot(ray)), 1e-6);
    EXPECT_NEAR((hits[k].normal_in_ahat - normal).norm(), 0.0, kNormalTol);  // the board's
  }
  EXPECT_EQ(hits[2].object, 0);  // 6 mm off the centre: bare board
  EXPECT_NEAR(hits[2].range_mm, board_range(outside), 1e-6);
  // It moves with the board: 50 mm farther, the sticker is still there and nothing floats.
  scene.objects[0].scene_from_object.translation.z() += 50.0;
  scene.tools[0].scene_from_tool.translation.z() += 50.0;
  raycaster.SetPoses(scene, Rigid3d::Identity());
  const RayHit moved = Cast(raycaster, {centre})[0];
  EXPECT_EQ(moved.marker, 0);
  EXPECT_NEAR(moved.range_mm, 550.0 - 0.1 / std::abs(normal.z()), 1e-6);
}

}  // namespace
}  // namespace tofnav::sim
