// SPDX-License-Identifier: BSD-3-Clause
// Physics acceptance of the simulator: noise law, skin and model bias, marker and skin AB, wrap,
// flying pixels and marker blob size (docs/tof_physics.md sections 3-8).
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>
#include <random>

#include "tofnav/sim/render.hpp"
#include "tofnav/sim/sim_test_scenes.hpp"

namespace tofnav::sim {
namespace {

using testing::BoardScene;
using testing::CentrePixel;
using testing::FacingPose;
using testing::TestCamera;
using testing::WindowAround;

RenderResult Render(const Scene& scene, const RenderOptions& options, std::uint64_t seed = 1) {
  std::mt19937_64 rng(seed);
  return RenderAhatFrame(scene, TestCamera(), Rigid3d::Identity(), options, rng);
}

// Range [mm] along pixel (u, v)'s centre ray to the board of FacingPose(distance, tilt).
double BoardRangeMm(int u, int v, double distance_mm, double tilt_rad = 0.0) {
  const Eigen::Vector3d n = FacingPose(distance_mm, tilt_rad).rotation * Eigen::Vector3d::UnitZ();
  return distance_mm * n.z() / n.dot(*TestCamera().Ray({u, v}));
}

template <typename F>
void ForEachPixel(const PixelRect& w, int margin, F&& f) {
  for (int v = w.v0 + margin; v < w.v0 + w.height - margin; ++v) {
    for (int u = w.u0 + margin; u < w.u0 + w.width - margin; ++u) f(u, v);
  }
}

TEST(RenderPhysics, DepthNoiseFollowsTheConfiguredSigmaLaw) {
  constexpr double kRelativeTol = 0.10;  // acceptance: std within 10 % of the law
  constexpr int kMarginPx = 4;           // beyond the correlation kernel's reach of the border
  RenderOptions options;
  options.bias_mode = BiasMode::kNone;
  options.sensor.wiggle_amplitude_mm = 0.0;
  options.scatter.wide_fraction = options.scatter.narrow_fraction = 0.0;
  options.supersampling = 1;
  options.jitter = false;
  options.window = WindowAround(CentrePixel().x(), CentrePixel().y(), 72);
  for (const double distance_mm : {400.0, 600.0, 800.0}) {  // sigma ~ 0.8, 1.2, 1.6 mm
    const RenderResult r = Render(BoardScene(DiffuseMaterial(0.5), distance_mm), options);
    double sum = 0.0, sum2 = 0.0, law2 = 0.0;
    int n = 0;
    ForEachPixel(options.window, kMarginPx, [&](int u, int v) {
      const double error = r.frame.range_mm(u, v) - BoardRangeMm(u, v, distance_mm);
      sum += error;
      sum2 += error * error;
      const double sigma =
          DepthNoiseSigmaMm(options.noise, r.frame.ab(u, v), BoardRangeMm(u, v, distance_mm));
      law2 += sigma * sigma + 1.0 / 12.0;  // plus the 1 mm rounding
      ++n;
    });
    const double mean = sum / n, std = std::sqrt(sum2 / n - mean * mean);
    EXPECT_NEAR(mean, 0.0, 0.1) << distance_mm;
    EXPECT_NEAR(std, std::sqrt(law2 / n), kRelativeTol * std::sqrt(law2 / n)) << distance_mm;
  }
}

TEST(RenderPhysics, SkinBiasAt500MmIsTheSubsurfacePhasorBias) {
  constexpr double kBiasTolMm = 0.2;  // acceptance
  constexpr double kDistanceMm = 500.0;
  RenderOptions options = IdealRenderOptions();
  options.bias_mode = BiasMode::kPhysical;
  options.window = WindowAround(CentrePixel().x(), CentrePixel().y(), 64);
  const Material skin = SkinMaterial();
  const RenderResult r = Render(BoardScene(skin, kDistanceMm), options);
  const double omega_tau =
      2.0 * std::numbers::pi * 299792458e3 / (2.0 * 1055.0) * skin.subsurface_delay_ps * 1e-12;
  double measured = 0.0, expected = 0.0;
  int n = 0;
  ForEachPixel(options.window, 0, [&](int u, int v) {
    const double theta = r.truth_incidence_rad(u, v);
    const double a = skin.subsurface_fraction * (1.0 + skin.subsurface_angle_gain_per_rad * theta);
    const std::complex<double> h = (1.0 - a) + a / std::complex<double>(1.0, omega_tau);
    const double subsurface_mm = -1055.0 / (2.0 * std::numbers::pi) * std::arg(h);
    const double intensity_mm = skin.intensity_bias_gain_mm * std::log(130.0 / r.frame.ab(u, v));
    expected += subsurface_mm + intensity_mm;
    measured += r.frame.range_mm(u, v) - BoardRangeMm(u, v, kDistanceMm);
    ++n;
  });
  EXPECT_NEAR(measured / n, expected / n, kBiasTolMm);
  EXPECT_GT(expected / n, 6.0);  // the paper's skin bias is 7.58 +- 1.49 mm
  EXPECT_LT(expected / n, 9.0);
}

TEST(RenderPhysics, ModelModeAddsC1PlusC2dPlusC3Theta) {
  constexpr double kDistanceMm = 480.0, kTiltRad = 0.5;
  RenderOptions options = IdealRenderOptions();
  options.bias_mode = BiasMode::kModel;
  options.window = WindowAround(CentrePixel().x(), CentrePixel().y(), 40);
  const Material nylon = NylonMaterial();
  const RenderResult r = Render(BoardScene(nylon, kDistanceMm, kTiltRad), options);
  const Eigen::Vector3d n = FacingPose(kDistanceMm, kTiltRad).rotation * Eigen::Vector3d::UnitZ();
  ForEachPixel(options.window, 0, [&](int u, int v) {
    const double d = BoardRangeMm(u, v, kDistanceMm, kTiltRad);
    const double theta = std::acos(std::abs(n.dot(*TestCamera().Ray({u, v}))));
    const double biased =
        d + nylon.model_c1_mm + nylon.model_c2 * d + nylon.model_c3_mm_per_rad * theta;
    EXPECT_NEAR(r.frame.range_mm(u, v), biased, 0.5 + 1e-6);  // rounding only
  });
}

TEST(RenderPhysics, RetroSheetingReadsFartherByItsEntranceAngleGain) {
  constexpr double kDistanceMm = 450.0, kTiltRad = 0.5, kGainMmPerRad = 2.1;
  RenderOptions options = IdealRenderOptions();  // f_rf's curve and the angle term, nothing else
  options.bias_mode = BiasMode::kPhysical;
  options.window = WindowAround(CentrePixel().x(), CentrePixel().y(), 30);
  Material tape = RetroReflectiveMaterial(RetroCurve::kNone);
  EXPECT_EQ(tape.retro_angle_gain_mm_per_rad, kGainMmPerRad);  // the preset's (calibrated) gain
  tape.retro_angle_gain_mm_per_rad = 0.0;
  const RenderResult flat = Render(BoardScene(tape, kDistanceMm, kTiltRad), options);
  tape.retro_angle_gain_mm_per_rad = kGainMmPerRad;
  const RenderResult tilted = Render(BoardScene(tape, kDistanceMm, kTiltRad), options);
  const Eigen::Vector3d n = FacingPose(kDistanceMm, kTiltRad).rotation * Eigen::Vector3d::UnitZ();
  double measured = 0.0, expected = 0.0;
  int count = 0;
  ForEachPixel(options.window, 0, [&](int u, int v) {
    if (tilted.frame.range_mm(u, v) == 0 || flat.frame.range_mm(u, v) == 0) return;
    measured += tilted.frame.range_mm(u, v) - flat.frame.range_mm(u, v);
    expected += kGainMmPerRad * std::acos(std::abs(n.dot(*TestCamera().Ray({u, v}))));
    ++count;
  });
  ASSERT_GT(count, 100);
  // Whole-millimetre ranges: the mean of the rounding differences is within a few tenths.
  EXPECT_NEAR(measured / count, expected / count, 0.3);
  EXPECT_GT(expected / count, 0.9);  // about 0.5 rad x 2.1 mm/rad: the term is there to see
}

TEST(RenderPhysics, MarkersExceedAndSkinStaysBelowTrackerThresholds) {
  constexpr double kMarkerThreshold = 1280.0;  // IRToolTrack
  constexpr double kSkinThreshold = 720.0;     // HL2-DINO
  const Eigen::Vector2i c = CentrePixel();
  for (const double distance_mm : {300.0, 500.0, 700.0}) {
    RenderOptions options;  // realistic defaults, noise included
    options.window = WindowAround(c.x(), c.y(), 24);
    Scene scene = BoardScene(SkinMaterial(), distance_mm);
    const RenderResult skin = Render(scene, options);
    ForEachPixel(options.window, 0, [&](int u, int v) {
      ASSERT_LT(skin.frame.ab(u, v), kSkinThreshold) << distance_mm;
    });
    const int retro = scene.AddMaterial(RetroReflectiveMaterial());
    scene.objects[0].scene_from_object = FacingPose(distance_mm + 50.0);
    scene.AddTool({"ball",
                   {SphereMarker({0, 0, 0}, 10.0, retro)},
                   Rigid3d(Eigen::Quaterniond::Identity(), {0, 0, distance_mm + 5.0})});
    const RenderResult marker = Render(scene, options);
    EXPECT_GT(marker.frame.ab(c.x(), c.y()), kMarkerThreshold) << distance_mm;
  }
}

TEST(RenderPhysics, RangesWrapAt1055Mm) {
  RenderOptions options = IdealRenderOptions();
  options.window = WindowAround(CentrePixel().x(), CentrePixel().y(), 32);
  const RenderResult r = Render(BoardScene(DiffuseMaterial(0.5), 1200.0), options);
  const Eigen::Vector2i c = CentrePixel();
  EXPECT_NEAR(r.frame.range_mm(c.x(), c.y()), 145.0, 1.0);
  ForEachPixel(options.window, 0, [&](int u, int v) {
    ASSERT_EQ(r.frame.range_mm(u, v), std::lround(BoardRangeMm(u, v, 1200.0) - 1055.0));
  });
}

TEST(RenderPhysics, FlyingPixelsLieOnlyAtDepthEdges) {
  constexpr double kFarFromTruthMm = 3.0;  // noise-free: rounding is 0.5 mm
  constexpr int kEdgeReachPx = 2;
  Scene scene = BoardScene(DiffuseMaterial(0.5), 900.0);
  scene.AddObject("box", BoxMesh({160.0, 160.0, 100.0}), 0,
                  Rigid3d(Eigen::Quaterniond::Identity(), {0.0, 0.0, 550.0}));  // front at 500 mm
  RenderOptions options = IdealRenderOptions();
  options.supersampling = 2;
  options.jitter = true;
  options.window = WindowAround(CentrePixel().x(), CentrePixel().y(), 96);
  const RenderResult r = Render(scene, options);
  int flying = 0;
  ForEachPixel(options.window, kEdgeReachPx, [&](int u, int v) {
    const double m = r.frame.range_mm(u, v);
    if (std::abs(m - BoardRangeMm(u, v, 500.0)) <= kFarFromTruthMm ||
        std::abs(m - BoardRangeMm(u, v, 900.0)) <= kFarFromTruthMm) {
      return;
    }
    ++flying;
    bool near_silhouette = false;
    for (int dv = -kEdgeReachPx; dv <= kEdgeReachPx; ++dv) {
      for (int du = -kEdgeReachPx; du <= kEdgeReachPx; ++du) {
        near_silhouette |= r.truth_object(u + du, v + dv) != r.truth_object(u, v);
      }
    }
    EXPECT_TRUE(near_silhouette) << "flying pixel away from the edge at " << u << ", " << v;
  });
  EXPECT_GT(flying, 40);  // the 80 mm box edge spans about 4 x 80 px; many straddle it
}

TEST(RenderPhysics, TenMillimetreMarkerAt500MmCoversAboutTwentyPixels) {
  constexpr double kRadiusPx = 254.0 * 5.0 / 500.0;
  constexpr double kExpectedPx = std::numbers::pi * kRadiusPx * kRadiusPx;  // 20.3 px
  constexpr double kRelativeTol = 0.30;                                     // acceptance
  // Pixels partly covered by the marker still pass the AB threshold (the marker is ~300 times
  // brighter than skin), so the thresholded blob lies between the covered area and the area
  // dilated by half a pixel diagonal.
  constexpr double kDilatedPx = std::numbers::pi * (kRadiusPx + 0.7072) * (kRadiusPx + 0.7072);
  const Eigen::Vector2i c = CentrePixel();
  for (const MarkerShape shape : {MarkerShape::kSphere, MarkerShape::kDisc}) {
    Scene scene = BoardScene(SkinMaterial(), 560.0);
    const int retro = scene.AddMaterial(RetroReflectiveMaterial());
    Marker marker{shape, 10.0, {0, 0, 0}, {0, 0, -1}, retro};
    scene.AddTool({"marker", {marker}, Rigid3d(Eigen::Quaterniond::Identity(), {0, 0, 500.0})});
    RenderOptions options;  // realistic defaults: 2 x 2 jittered sub-rays, noise, scatter
    options.window = WindowAround(c.x(), c.y(), 20);
    const RenderResult r = Render(scene, options);
    const int shape_id = static_cast<int>(shape);
    EXPECT_NEAR(r.markers[0].pixel_count, kExpectedPx, kRelativeTol * kExpectedPx) << shape_id;
    int bright = 0;
    ForEachPixel(options.window, 0,
                 [&](int u, int v) { bright += r.frame.ab(u, v) >= 1280 ? 1 : 0; });
    EXPECT_GE(bright, (1.0 - kRelativeTol) * kExpectedPx) << shape_id;
    EXPECT_LE(bright, (1.0 + kRelativeTol) * kDilatedPx) << shape_id;
  }
}

}  // namespace
}  // namespace tofnav::sim
