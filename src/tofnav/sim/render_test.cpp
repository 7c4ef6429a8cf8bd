// SPDX-License-Identifier: BSD-3-Clause
// Rendering mechanics: exact ideal ranges, invalidation codes, truth images, determinism.
#include "tofnav/sim/render.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "tofnav/sim/sim_test_scenes.hpp"

namespace tofnav::sim {
namespace {

using testing::BoardScene;
using testing::CentrePixel;
using testing::TestCamera;
using testing::WindowAround;

constexpr int kWindowPx = 48;

RenderResult Render(const Scene& scene, const RenderOptions& options, std::uint64_t seed = 1) {
  std::mt19937_64 rng(seed);
  return RenderAhatFrame(scene, TestCamera(), Rigid3d::Identity(), options, rng);
}

RenderOptions IdealWindow() {
  RenderOptions options = IdealRenderOptions();
  options.window = WindowAround(CentrePixel().x(), CentrePixel().y(), kWindowPx);
  return options;
}

TEST(RenderAhatFrame, IdealBoardReadsTheRoundedExactRange) {
  constexpr double kDistanceMm = 437.3;
  constexpr double kAlbedo = 0.5;
  const RenderOptions options = IdealWindow();
  const RenderResult r = Render(BoardScene(DiffuseMaterial(kAlbedo), kDistanceMm, 0.2), options);
  const Eigen::Vector3d normal =
      testing::FacingPose(kDistanceMm, 0.2).rotation * Eigen::Vector3d::UnitZ();
  const PixelRect& w = options.window;
  for (int v = w.v0; v < w.v0 + w.height; ++v) {
    for (int u = w.u0; u < w.u0 + w.width; ++u) {
      const Eigen::Vector3d ray = *TestCamera().Ray({u, v});
      const double range = kDistanceMm * normal.z() / normal.dot(ray);  // ray-plane intersection
      ASSERT_EQ(r.frame.range_mm(u, v), std::lround(range)) << u << ", " << v;
      EXPECT_NEAR(r.truth_range_mm(u, v), range, 1e-3);  // float image
      const double cos_incidence = std::abs(normal.dot(ray));
      const double ab = 65.0 * kAlbedo * cos_incidence * ray.z() * ray.z() / (range * range * 1e-6);
      EXPECT_EQ(r.frame.ab(u, v), std::lround(ab));
      EXPECT_NEAR(r.truth_incidence_rad(u, v), std::acos(cos_incidence), 1e-6);
      EXPECT_EQ(r.invalid_reason(u, v), static_cast<std::uint8_t>(InvalidReason::kValid));
      EXPECT_EQ(r.truth_object(u, v), 0);
      EXPECT_EQ(r.truth_bias_mm(u, v), 0.0f);
    }
  }
  // Outside the window nothing is rendered.
  EXPECT_EQ(r.frame.range_mm(0, 256), kOutsideIlluminationCode);
  EXPECT_EQ(r.invalid_reason(0, 256), static_cast<std::uint8_t>(InvalidReason::kNotRendered));
}

TEST(RenderAhatFrame, InvalidatesOutsideTheIlluminationCircleAndOnLowSignal) {
  RenderOptions options = IdealRenderOptions();
  options.window = {0, 0, 24, 24};  // the corner lies outside the 256 px circle
  const RenderResult corner = Render(BoardScene(DiffuseMaterial(0.5), 400.0), options);
  EXPECT_EQ(corner.frame.range_mm(3, 3), kOutsideIlluminationCode);
  EXPECT_EQ(corner.invalid_reason(3, 3),
            static_cast<std::uint8_t>(InvalidReason::kOutsideIllumination));
  EXPECT_EQ(corner.frame.ab(3, 3), 0);
  EXPECT_EQ(corner.truth_range_mm(3, 3), 0.0f);
  const Eigen::Vector2i c = CentrePixel();
  options.window = WindowAround(c.x(), c.y(), 8);
  EXPECT_LT(Render(BoardScene(DiffuseMaterial(0.5), 400.0), options).frame.range_mm(c.x(), c.y()),
            1055);
  // rho 0.5 at 2 m: AB = 65 * 0.5 / 4 = 8 < 10.
  const RenderResult far = Render(BoardScene(DiffuseMaterial(0.5), 2000.0), options);
  EXPECT_EQ(far.frame.range_mm(c.x(), c.y()), kLowSignalCode);
  EXPECT_EQ(far.invalid_reason(c.x(), c.y()), static_cast<std::uint8_t>(InvalidReason::kLowSignal));
  EXPECT_NEAR(far.truth_range_mm(c.x(), c.y()), 2000.0, 1.0);
  const RenderResult empty = Render(Scene{}, options);  // no return at all
  EXPECT_EQ(empty.frame.range_mm(c.x(), c.y()), kLowSignalCode);
  EXPECT_EQ(empty.truth_range_mm(c.x(), c.y()), 0.0f);
  EXPECT_EQ(empty.truth_material(c.x(), c.y()), -1);
}

TEST(RenderAhatFrame, IsDeterministicPerSeedAndIndependentOfTheWindow) {
  RenderOptions options;  // realistic: jitter, noise, bias
  options.scatter.wide_fraction = options.scatter.narrow_fraction = 0.0;  // window-local effects
  options.noise.depth_correlation_px = 0.0;
  const Scene scene = BoardScene(SkinMaterial(), 450.0, 0.4);
  options.window = {240, 240, 24, 24};
  const RenderResult a = Render(scene, options, 7);
  const RenderResult again = Render(scene, options, 7);
  EXPECT_EQ(a.frame.range_mm, again.frame.range_mm);
  EXPECT_EQ(a.frame.ab, again.frame.ab);
  const RenderResult other_seed = Render(scene, options, 8);
  EXPECT_NE(a.frame.range_mm, other_seed.frame.range_mm);
  options.window = {252, 250, 24, 24};
  const RenderResult shifted = Render(scene, options, 7);
  for (int v = 250; v < 264; ++v) {
    for (int u = 252; u < 264; ++u) {
      EXPECT_EQ(a.frame.range_mm(u, v), shifted.frame.range_mm(u, v));
      EXPECT_EQ(a.frame.ab(u, v), shifted.frame.ab(u, v));
    }
  }
}

TEST(RenderAhatFrame, ReportsMarkerTruthAndTheRigPose) {
  Scene scene = BoardScene(SkinMaterial(), 600.0);
  const int retro = scene.AddMaterial(RetroReflectiveMaterial());
  Tool tool{"pointer",
            {SphereMarker({0, 0, 0}, 12.0, retro), SphereMarker({0, 0, -2000}, 12.0, retro)},
            Rigid3d(Eigen::Quaterniond::Identity(), {10.0, -5.0, 400.0})};
  scene.AddTool(tool);
  RenderOptions options = IdealWindow();
  const RenderResult r = Render(scene, options);
  ASSERT_EQ(r.markers.size(), 2u);
  EXPECT_NEAR((r.markers[0].centre_in_ahat - Eigen::Vector3d(10.0, -5.0, 400.0)).norm(), 0.0,
              1e-12);
  EXPECT_GT(r.markers[0].pixel_count, 20);  // about (254 * 12 / 400)^2 * pi / 4 = 57 px
  EXPECT_EQ(r.markers[1].pixel_count, 0);   // behind the camera
  const Eigen::Vector2d centre = *TestCamera().Project(r.markers[0].centre_in_ahat);
  const int u = static_cast<int>(std::lround(centre.x())),
            v = static_cast<int>(std::lround(centre.y()));
  EXPECT_EQ(r.truth_marker(u, v), scene.MarkerId(0, 0));
  EXPECT_EQ(r.truth_material(u, v), retro);
  EXPECT_EQ(r.truth_object(u, v), -1);
  ASSERT_TRUE(r.frame.world_from_rig.has_value());
  EXPECT_NEAR(
      TranslationDistanceMm(*r.frame.world_from_rig, TestCamera().rig_from_ahat().Inverse()), 0.0,
      1e-12);
}

TEST(RenderOptions, CheckRejectsBadFields) {
  RenderOptions options;
  options.supersampling = 0;
  EXPECT_THROW(options.Check(), std::invalid_argument);
  options = RenderOptions{};
  options.window = {500, 0, 20, 10};
  EXPECT_THROW(options.Check(), std::invalid_argument);
  options = RenderOptions{};
  options.noise.ab_noise_scale = -1.0;
  EXPECT_THROW(options.Check(), std::invalid_argument);
}

}  // namespace
}  // namespace tofnav::sim
