// SPDX-License-Identifier: BSD-3-Clause
// Damage flags of LocateMarkers on simulated frames: image border, merged, near, occluded, and
// no flag on a whole marker on a steep plate (docs/tracking.md section 6).
#include "tofnav/markers/marker_damage.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

#include "marker_test_scenes.hpp"
#include "tofnav/markers/marker_detection.hpp"

namespace tofnav {
namespace {

using testing::TestCamera;

constexpr double kSphereDiameterMm = 11.5;

sim::RenderResult RenderScene(const sim::Scene& scene, std::uint64_t seed = 3) {
  sim::RenderOptions options;
  options.supersampling = 4;
  return testing::RenderMarkers(scene, seed, options);
}

sim::Scene SpheresScene(const Points3d& centres_in_ahat, int& diffuse) {
  int retro = 0;
  sim::Scene scene = testing::WallScene(centres_in_ahat[0].z() + 250.0, retro);
  diffuse = scene.AddMaterial(sim::DiffuseMaterial(0.5));
  scene.AddTool(
      testing::SphereTool("balls", centres_in_ahat, kSphereDiameterMm, retro, Rigid3d::Identity()));
  return scene;
}

double AngleRad(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

TEST(MarkerDamage, ABlobCutByTheImageBorderIsDroppedWithItsPlace) {
  // A sphere centred on the ray of pixel (1.5, 300): the sensor's illumination ends at column 1
  // there, so the blob is cut by the edge of the field (pixel 0 has no signal at all).
  const Eigen::Vector3d centre = 400.0 * TestCamera().Ray({1.5, 300.0})->normalized();
  int diffuse = 0;
  const MarkerDetectionResult r =
      LocateMarkers(RenderScene(SpheresScene({centre}, diffuse)).frame, TestCamera());
  EXPECT_TRUE(r.markers.empty());
  EXPECT_EQ(r.rejected.border, 1);
  ASSERT_EQ(r.dropped.size(), 1u);
  EXPECT_EQ(r.dropped[0].reason, BlobDropReason::kImageBorder);
  // Its place: the visible part's mean pixel, within one marker radius of the true direction.
  EXPECT_LT(AngleRad(r.dropped[0].ray_in_ahat, centre), 0.5 * kSphereDiameterMm / centre.norm());
  EXPECT_GT(r.dropped[0].radius_rad, 0.0);
}

TEST(MarkerDamage, TwoTouchingSpheresAreOneMergedBlobAndDropped) {
  // 12 mm apart at 450 mm: a 0.5 mm gap, a quarter pixel, so one blob twice a marker long.
  int diffuse = 0;
  const MarkerDetectionResult r = LocateMarkers(
      RenderScene(SpheresScene({{-6.0, 10.0, 450.0}, {6.0, 10.0, 450.0}}, diffuse)).frame,
      TestCamera());
  EXPECT_TRUE(r.markers.empty());
  EXPECT_EQ(r.rejected.merged, 1);
  ASSERT_EQ(r.dropped.size(), 1u);
  EXPECT_EQ(r.dropped[0].reason, BlobDropReason::kMerged);
}

TEST(MarkerDamage, TwoSpheresAFewPixelsApartAreNearBlobs) {
  // 15 mm apart at 450 mm: a 3.5 mm gap, about 2 px between the blobs.
  int diffuse = 0;
  const MarkerDetectionResult r = LocateMarkers(
      RenderScene(SpheresScene({{-7.5, 10.0, 450.0}, {7.5, 10.0, 450.0}}, diffuse)).frame,
      TestCamera());
  ASSERT_EQ(r.markers.size(), 2u);
  for (const DetectedMarker& m : r.markers) {
    EXPECT_TRUE(m.damage.near_blob);
    EXPECT_FALSE(m.damage.occluded);
  }
}

TEST(MarkerDamage, ASphereHalfBehindABoxIsOccludedAndAWholeOneIsNot) {
  const Eigen::Vector3d centre(20.0, -10.0, 450.0);
  int diffuse = 0;
  sim::Scene scene = SpheresScene({centre}, diffuse);
  const MarkerDetectionResult whole = LocateMarkers(RenderScene(scene).frame, TestCamera());
  ASSERT_EQ(whole.markers.size(), 1u);
  EXPECT_FALSE(whole.markers[0].damage.Any());
  EXPECT_EQ(whole.markers[0].damage.occluder_px, 0);
  EXPECT_GT(whole.markers[0].damage.ring_px, 20);
  // A 40 x 40 x 5 mm box 40 mm in front whose left edge is on the sphere's line of sight.
  constexpr double kDepthMm = 410.0;
  const Eigen::Vector3d edge = centre * (kDepthMm / centre.z());
  scene.AddObject("box", sim::BoxMesh({40.0, 40.0, 5.0}), diffuse,
                  Rigid3d(Eigen::Quaterniond::Identity(), edge + Eigen::Vector3d(20.0, 0.0, 0.0)));
  const MarkerDetectionResult cut = LocateMarkers(RenderScene(scene).frame, TestCamera());
  ASSERT_EQ(cut.markers.size(), 1u);
  EXPECT_TRUE(cut.markers[0].damage.occluded);
  EXPECT_GE(cut.markers[0].damage.occluder_px, 5);
}

TEST(MarkerDamage, ADiscOnAPlateTiltedBy55DegreesIsNotOccluded) {
  // The plate around a tape disc rises towards the camera on one side; the margin allows for it.
  for (const double range_mm : {350.0, 700.0}) {
    sim::Scene scene;
    const int plate = scene.AddMaterial(sim::DiffuseMaterial(0.6));
    const int tape = scene.AddMaterial(sim::RetroReflectiveMaterial(sim::RetroCurve::kLinear));
    const Eigen::Quaterniond facing(
        Eigen::AngleAxisd(55.0 * std::numbers::pi / 180.0, Eigen::Vector3d::UnitY()) *
        Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitX()));
    const Rigid3d pose(facing, Eigen::Vector3d(10.0, 5.0, range_mm));
    scene.AddObject("plate", sim::PlaneMesh(200.0, 200.0), plate, pose);
    scene.AddTool(
        {"tape",
         {sim::DiscMarkerOnSurface(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 10.0, tape)},
         pose});
    const MarkerDetectionResult r = LocateMarkers(RenderScene(scene).frame, TestCamera());
    ASSERT_EQ(r.markers.size(), 1u) << range_mm;
    EXPECT_FALSE(r.markers[0].damage.Any()) << range_mm;
  }
}

TEST(MarkerDamage, BlobShapeIsTheDiameterOfADisc) {
  constexpr double kTolPx = 0.1;  // a pixelated disc of radius 6: rim quantisation
  std::vector<PixelRun> runs;
  int area = 0;
  for (int v = -6; v <= 6; ++v) {
    const int half = static_cast<int>(std::floor(std::sqrt(36.5 - v * v)));
    runs.push_back({100 + v, 200 - half, 200 + half + 1});
    area += 2 * half + 1;
  }
  const BlobShape shape = MeasureBlobShape(runs);
  EXPECT_NEAR(shape.mean.x(), 200.0, 1e-12);
  EXPECT_NEAR(shape.mean.y(), 100.0, 1e-12);
  // The diameter of the disc of the same area.
  EXPECT_NEAR(shape.length_px, 2.0 * std::sqrt(area / std::numbers::pi), kTolPx);
}

}  // namespace
}  // namespace tofnav
