// SPDX-License-Identifier: BSD-3-Clause
// LocateMarkers on simulated frames (accuracy, wrap, rejects) and on hostile synthetic frames.
#include "tofnav/markers/marker_detection.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>

#include "marker_test_scenes.hpp"
#include "tofnav/markers/marker_centre.hpp"

namespace tofnav {
namespace {

using testing::TestCamera;

constexpr double kSphereDiameterMm = 11.5;  // NDI-style

sim::Scene OneSphereScene(const Eigen::Vector3d& centre_in_ahat, double diameter_mm,
                          sim::RetroCurve curve = sim::RetroCurve::kNone) {
  int retro = 0;
  sim::Scene scene = testing::WallScene(centre_in_ahat.z() + 250.0, retro, curve);
  scene.AddTool({"ball",
                 {sim::SphereMarker(Eigen::Vector3d::Zero(), diameter_mm, retro)},
                 Rigid3d(Eigen::Quaterniond::Identity(), centre_in_ahat)});
  return scene;
}

// Splits a centre error into the part along the true ray and the lateral rest [mm].
Eigen::Vector2d RangeAndLateralError(const Eigen::Vector3d& measured,
                                     const Eigen::Vector3d& truth) {
  const Eigen::Vector3d dir = truth.normalized();
  const Eigen::Vector3d e = measured - truth;
  return {e.dot(dir), (e - e.dot(dir) * dir).norm()};
}

TEST(LocateMarkers, IdealSphereGivesItsCentre) {
  constexpr double kLateralTolMm = 0.05;  // noise-free, 1 ray per pixel: centroid symmetry only
  constexpr double kRangeTolMm = 0.5;     // ranges are rounded to 1 mm
  const Eigen::Vector3d truth(30.0, -20.0, 400.0);
  sim::RenderOptions options = sim::IdealRenderOptions();
  options.supersampling = 4;  // anti-aliased rim: no snapping of the centroid to pixel centres
  const sim::RenderResult r =
      testing::RenderMarkers(OneSphereScene(truth, kSphereDiameterMm), 1, options);
  const MarkerDetectionResult detected = LocateMarkers(r.frame, TestCamera());
  ASSERT_EQ(detected.markers.size(), 1u);
  const Eigen::Vector2d e =
      RangeAndLateralError(MarkerCentre(detected.markers[0], kSphereDiameterMm / 2), truth);
  EXPECT_NEAR(e.x(), 0.0, kRangeTolMm);
  EXPECT_LT(e.y(), kLateralTolMm);
  EXPECT_GT(static_cast<int>(detected.markers[0].core.size()), 10);
}

TEST(LocateMarkers, RealisticSpheresAreWithinAFewTenthsAcrossTheWorkingRange) {
  // Acceptance: no f_rf, wiggle off; noise averages. The sheeting's entrance-angle term (about
  // +1 mm over a sphere's face, docs/tracking.md 4) is taken off as tracking does, per core pixel.
  // 16 frames per range: at 700 mm one pixel's range sd is 0.85 mm (the calibrated noise floor,
  // docs/simulator.md 10.1), so a 2-frame mean scattered by +-0.3 mm; 16 show the bias itself.
  constexpr double kMeanRangeTolMm = 0.25;
  const double gain_mm_per_rad = sim::RetroReflectiveMaterial().retro_angle_gain_mm_per_rad;
  constexpr double kLateralRmsTolMm = 0.25;  // over the 16 frames (one frame: up to 0.26 far)
  sim::RenderOptions options;
  options.sensor.wiggle_amplitude_mm = 0.0;
  for (const double z_mm : {300.0, 500.0, 700.0}) {
    double range_sum = 0.0, lateral2 = 0.0;
    constexpr int kFrames = 16;
    for (int seed = 0; seed < kFrames; ++seed) {
      const Eigen::Vector3d truth(-40.0 + 5.0 * seed, 25.0, z_mm);
      const sim::RenderResult r = testing::RenderMarkers(OneSphereScene(truth, kSphereDiameterMm),
                                                         static_cast<std::uint64_t>(seed), options);
      const MarkerDetectionResult detected = LocateMarkers(r.frame, TestCamera());
      ASSERT_EQ(detected.markers.size(), 1u) << z_mm;
      DetectedMarker marker = detected.markers[0];
      ShiftSphereEntranceAngles(
          marker, marker.ray_in_ahat * (marker.surface_range_mm + kSphereDiameterMm / 2),
          kSphereDiameterMm / 2, gain_mm_per_rad);
      const Eigen::Vector2d e =
          RangeAndLateralError(MarkerCentre(marker, kSphereDiameterMm / 2), truth);
      range_sum += e.x();
      lateral2 += e.y() * e.y();
    }
    const double lateral_rms = std::sqrt(lateral2 / kFrames);
    std::printf("z %.0f mm: mean range error %.3f mm, lateral RMS %.3f mm\n", z_mm,
                range_sum / kFrames, lateral_rms);
    EXPECT_LT(lateral_rms, kLateralRmsTolMm) << z_mm;
    EXPECT_NEAR(range_sum / kFrames, 0.0, kMeanRangeTolMm) << z_mm;
  }
}

TEST(LocateMarkers, RejectsAPhaseWrappedMarkerByItsSize) {
  // A 30 mm ball at 1300 mm reads about 245 mm; at that range it would look 5x wider.
  sim::Scene scene;
  const int retro = scene.AddMaterial(sim::RetroReflectiveMaterial(sim::RetroCurve::kNone));
  scene.AddTool({"far",
                 {sim::SphereMarker({0, 0, 0}, 20.0, retro)},
                 Rigid3d(Eigen::Quaterniond::Identity(), {0.0, 0.0, 1300.0})});
  const sim::RenderResult r = testing::RenderMarkers(scene, 3, sim::IdealRenderOptions());
  const MarkerDetectionResult detected = LocateMarkers(r.frame, TestCamera());
  EXPECT_TRUE(detected.markers.empty());
  EXPECT_EQ(detected.rejected.size_range, 1);
}

AhatFrame SyntheticFrame(std::uint16_t ab, std::uint16_t range_mm) {
  AhatFrame frame;
  frame.ab = Image<std::uint16_t>(kAhatWidth, kAhatHeight, ab);
  frame.range_mm = Image<std::uint16_t>(kAhatWidth, kAhatHeight, range_mm);
  return frame;
}

// A Gaussian spot of peak `peak` and sigma `sigma_px` added to the AB image.
void AddSpot(AhatFrame& frame, double u0, double v0, double peak, double sigma_px) {
  for (int v = static_cast<int>(v0) - 10; v <= static_cast<int>(v0) + 10; ++v) {
    for (int u = static_cast<int>(u0) - 10; u <= static_cast<int>(u0) + 10; ++u) {
      if (!frame.ab.Contains(u, v)) continue;
      const double d2 = (u - u0) * (u - u0) + (v - v0) * (v - v0);
      const double value = frame.ab(u, v) + peak * std::exp(-0.5 * d2 / (sigma_px * sigma_px));
      frame.ab(u, v) = static_cast<std::uint16_t>(std::min(65535.0, value));
    }
  }
}

TEST(LocateMarkers, ReturnsNothingForEmptyOrSaturatedFramesAndNeverThrows) {
  EXPECT_TRUE(LocateMarkers(SyntheticFrame(0, 0), TestCamera()).markers.empty());
  const MarkerDetectionResult saturated = LocateMarkers(SyntheticFrame(65535, 500), TestCamera());
  EXPECT_TRUE(saturated.markers.empty());
  EXPECT_EQ(saturated.blob_count, 1);
  EXPECT_EQ(saturated.rejected.area, 1);
  // Bright spots whose ranges are all invalid (0 or >= 4090) have no depth.
  for (const std::uint16_t invalid : {std::uint16_t{0}, std::uint16_t{4093}}) {
    AhatFrame frame = SyntheticFrame(100, invalid);
    AddSpot(frame, 250.3, 260.7, 30000.0, 2.0);
    const MarkerDetectionResult r = LocateMarkers(frame, TestCamera());
    EXPECT_TRUE(r.markers.empty());
    EXPECT_EQ(r.rejected.no_depth, 1);
  }
}

TEST(LocateMarkers, FindsTheSubPixelCentroidAndRejectsBorderBlobs) {
  constexpr double kCentroidTolPx = 0.01;  // symmetric synthetic spot
  AhatFrame frame = SyntheticFrame(100, 400);
  AddSpot(frame, 250.3, 260.7, 30000.0, 2.0);
  AddSpot(frame, 3.0, 200.0, 30000.0, 2.0);  // clipped by the image border
  const MarkerDetectionResult r = LocateMarkers(frame, TestCamera());
  ASSERT_EQ(r.markers.size(), 1u);
  EXPECT_NEAR(r.markers[0].pixel.x(), 250.3, kCentroidTolPx);
  EXPECT_NEAR(r.markers[0].pixel.y(), 260.7, kCentroidTolPx);
  EXPECT_NEAR((r.markers[0].ray_in_ahat - *TestCamera().Ray(r.markers[0].pixel)).norm(), 0.0,
              1e-12);
  EXPECT_DOUBLE_EQ(r.markers[0].surface_range_mm, 400.0);
  EXPECT_EQ(r.rejected.border, 1);
  ASSERT_EQ(r.dropped.size(), 1u);
  EXPECT_EQ(r.dropped[0].reason, BlobDropReason::kImageBorder);
  EXPECT_NEAR(r.dropped[0].pixel.y(), 200.0, 0.5);  // symmetric about its row
}

TEST(LocateMarkers, AdaptiveThresholdSplitsSpotsJoinedByAGlow) {
  AhatFrame frame = SyntheticFrame(100, 400);
  for (int v = 240; v < 262; ++v) {
    for (int u = 240; u < 270; ++u) frame.ab(u, v) = 1500;  // glow above the fixed threshold
  }
  AddSpot(frame, 248.0, 250.0, 30000.0, 1.5);
  AddSpot(frame, 260.0, 251.0, 30000.0, 1.5);
  MarkerDetectionOptions options;
  // Let the joined glow (30 px long, ~45 mm at 400 mm) pass the size and merged gates.
  options.max_marker_diameter_mm = 60.0;
  EXPECT_EQ(LocateMarkers(frame, TestCamera(), options).markers.size(), 1u);
  options.relative_threshold = 2.0;  // twice the bright background
  const MarkerDetectionResult adaptive = LocateMarkers(frame, TestCamera(), options);
  EXPECT_GT(adaptive.ab_threshold, 1500.0);
  EXPECT_EQ(adaptive.markers.size(), 2u);
}

TEST(LocateMarkers, RejectsMarkersWhereTheRayTableIsInvalid) {
  AhatCalibration calibration = MakeSyntheticAhatCalibration();
  for (int v = 200; v < 260; ++v) {
    for (int u = 330; u < 390; ++u) {
      calibration.uv2xy(u, v).setConstant(std::numeric_limits<float>::quiet_NaN());
    }
  }
  const AhatCamera holed(calibration);
  AhatFrame frame = SyntheticFrame(100, 400);
  AddSpot(frame, 360.0, 230.0, 30000.0, 2.0);
  const MarkerDetectionResult r = LocateMarkers(frame, holed);
  EXPECT_TRUE(r.markers.empty());
  EXPECT_EQ(r.rejected.invalid_ray, 1);
}

TEST(LocateMarkers, ChecksOptionsAndImageSizes) {
  MarkerDetectionOptions options;
  options.ab_threshold = 0.0;
  EXPECT_THROW(options.Check(), std::invalid_argument);
  options = {};
  options.core_ab_fraction = 1.5;
  EXPECT_THROW(options.Check(), std::invalid_argument);
  AhatFrame small;
  small.ab = Image<std::uint16_t>(16, 16, 0);
  small.range_mm = Image<std::uint16_t>(16, 16, 0);
  EXPECT_THROW(LocateMarkers(small, TestCamera()), std::invalid_argument);
}

}  // namespace
}  // namespace tofnav
