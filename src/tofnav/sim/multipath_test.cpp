// SPDX-License-Identifier: BSD-3-Clause
// One-bounce multipath: nothing on a flat board or a convex corner, a longer range in a concave
// one.
#include "tofnav/sim/multipath.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <initializer_list>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "tofnav/sim/render.hpp"
#include "tofnav/sim/sim_test_scenes.hpp"

namespace tofnav::sim {
namespace {

using testing::BoardScene;
using testing::CentrePixel;
using testing::TestCamera;
using testing::WindowAround;

RenderResult Render(const Scene& scene, const RenderOptions& options) {
  std::mt19937_64 rng(1);
  return RenderAhatFrame(scene, TestCamera(), Rigid3d::Identity(), options, rng);
}

RenderOptions IdealWithMultipath(double gain) {
  RenderOptions options = IdealRenderOptions();
  options.window = WindowAround(CentrePixel().x(), CentrePixel().y(), 128);
  options.multipath = {gain, 8, 8};
  return options;
}

// A width x height plane (like PlaneMesh) carrying bumps of `amplitude_mm` on a square grid of
// `wavelength_mm`, triangulated every millimetre: a surface rough at a few pixels' scale.
TriangleMesh BumpyPlaneMesh(double width_mm, double height_mm, double wavelength_mm,
                            double amplitude_mm) {
  TriangleMesh mesh;
  const int nx = static_cast<int>(width_mm) + 1, ny = static_cast<int>(height_mm) + 1;
  const double k = 2.0 * std::numbers::pi / wavelength_mm;
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const double x = i - 0.5 * width_mm, y = j - 0.5 * height_mm;
      mesh.vertices.emplace_back(x, y, amplitude_mm * std::sin(k * x) * std::sin(k * y));
    }
  }
  for (int j = 0; j + 1 < ny; ++j) {
    for (int i = 0; i + 1 < nx; ++i) {
      const int a = j * nx + i;
      mesh.triangles.emplace_back(a, a + 1, a + nx + 1);
      mesh.triangles.emplace_back(a, a + nx + 1, a + nx);
    }
  }
  return mesh;
}

// Two 200 x 400 mm walls meeting at 90 degrees in a vertical crease at x = 0, z = 500 mm, both
// at 45 degrees to the optical axis: open toward the camera (concave) or pointing at it (convex);
// with `bump_amplitude_mm` > 0, rough (bumps 6 mm apart).
Scene CornerScene(bool concave, double bump_amplitude_mm = 0.0,
                  const Material& material = DiffuseMaterial(0.8)) {
  Scene scene;
  const int m = scene.AddMaterial(material);
  const Eigen::Quaterniond flip(Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitX()));
  const double half = 100.0 * std::numbers::sqrt2 / 2.0, depth = concave ? -half : half;
  for (const double side : {-1.0, 1.0}) {
    const double tilt_rad = (concave ? side : -side) * std::numbers::pi / 4.0;
    const Eigen::Quaterniond tilt(Eigen::AngleAxisd(tilt_rad, Eigen::Vector3d::UnitY()));
    scene.AddObject(side < 0 ? "left" : "right",
                    bump_amplitude_mm > 0.0 ? BumpyPlaneMesh(200.0, 400.0, 6.0, bump_amplitude_mm)
                                            : PlaneMesh(200.0, 400.0),
                    m, Rigid3d(tilt * flip, {side * half, 0.0, 500.0 + depth}));
  }
  return scene;
}

// Mean range difference [mm] of `on` minus `off` over pixels left (side -1) or right (+1) of the
// crease, at least 3 px from it; every difference checked against the bounds.
double MeanBiasMm(const RenderResult& on, const RenderResult& off, int side) {
  constexpr double kRoundingMm = 1.0;             // both depths are rounded to 1 mm
  constexpr double kUpperBoundMm = 1055.0 / 4.0;  // (L / 2 pi) atan(.) < L / 4 for any ratio
  const Eigen::Vector2i c = CentrePixel();
  double sum = 0.0;
  int count = 0;
  for (int v = c.y() - 40; v <= c.y() + 40; ++v) {
    for (int du = 3; du <= 60; ++du) {
      const int u = c.x() + side * du;
      if (off.truth_range_mm(u, v) <= 0.0f) continue;
      const double bias = on.frame.range_mm(u, v) - off.frame.range_mm(u, v);
      EXPECT_GE(bias, -kRoundingMm) << u << ", " << v;
      EXPECT_LT(bias, kUpperBoundMm) << u << ", " << v;
      sum += bias;
      ++count;
    }
  }
  EXPECT_GT(count, 1000);
  return sum / std::max(count, 1);
}

// The left wall's mean shift [mm] with blocks of each stride (emitters and receivers alike).
std::vector<double> LeftWallShiftsMm(const Scene& scene, std::initializer_list<int> strides) {
  const RenderResult off = Render(scene, IdealWithMultipath(0.0));
  std::vector<double> shift_mm;
  for (const int stride : strides) {
    RenderOptions options = IdealWithMultipath(1.0);
    options.multipath.source_stride_px = options.multipath.receiver_stride_px = stride;
    shift_mm.push_back(MeanBiasMm(Render(scene, options), off, -1));
    ::testing::Test::RecordProperty("mean_bias_" + std::to_string(stride) + "px_mm",
                                    std::to_string(shift_mm.back()));
  }
  return shift_mm;
}

TEST(Multipath, AConcaveCornerReadsFartherSymmetricallyAndMoreWithGain) {
  constexpr double kMinBiasMm = 1.0;   // mm-level in concavities (docs/tof_physics.md 6.2)
  constexpr double kSymmetryMm = 0.3;  // mirror-symmetric scene; the grids are not exactly
  const Scene scene = CornerScene(true);
  const RenderResult off = Render(scene, IdealWithMultipath(0.0));
  const RenderResult half = Render(scene, IdealWithMultipath(0.5));
  const RenderResult on = Render(scene, IdealWithMultipath(1.0));
  const double left_mm = MeanBiasMm(on, off, -1), right_mm = MeanBiasMm(on, off, 1);
  EXPECT_GT(left_mm, kMinBiasMm);
  EXPECT_NEAR(left_mm, right_mm, kSymmetryMm);
  // The phase pull atan(g a) grows with the gain, less than linearly.
  const double half_mm = MeanBiasMm(half, off, -1);
  RecordProperty("mean_bias_left_mm", std::to_string(left_mm));
  RecordProperty("mean_bias_right_mm", std::to_string(right_mm));
  RecordProperty("mean_bias_left_half_gain_mm", std::to_string(half_mm));
  EXPECT_GT(half_mm, 0.3 * left_mm);
  EXPECT_LT(half_mm, 0.8 * left_mm);
}

TEST(Multipath, IndirectLightIsDelayedAtBothScatterings) {
  // Walls that delay the light they scatter (subsurface, 52 ps: 7.4 mm of range at 142 MHz). Their
  // direct light is delayed once, the indirect light twice, so relative to the direct light the
  // indirect path is 2 x 7.4 mm longer than on delay-free walls, and it pulls the phase further:
  // on this corner the exchange's own path d_j + r - d_i is short (tens of mm), so the shift
  // grows by far more than the rounding. The delay itself must not count as a shift: both
  // renderings carry it.
  constexpr double kMinGrowthMm = 0.5;  // measured 1.1 mm (8.6 against 7.5)
  Material delaying = DiffuseMaterial(0.8);
  delaying.subsurface_fraction = 1.0;
  delaying.subsurface_delay_ps = 52.0;
  RenderOptions off = IdealWithMultipath(0.0), on = IdealWithMultipath(1.0);
  off.bias_mode = on.bias_mode = BiasMode::kPhysical;
  const Scene delayed = CornerScene(true, 0.0, delaying), plain = CornerScene(true);
  const double delayed_mm = MeanBiasMm(Render(delayed, on), Render(delayed, off), -1);
  const double plain_mm = MeanBiasMm(Render(plain, on), Render(plain, off), -1);
  RecordProperty("mean_bias_delayed_mm", std::to_string(delayed_mm));
  RecordProperty("mean_bias_plain_mm", std::to_string(plain_mm));
  EXPECT_GT(delayed_mm, plain_mm + kMinGrowthMm);
}

TEST(Multipath, AConcaveCornersShiftConvergesAsTheBlocksShrink) {
  // The walls are 200 mm wide, several blocks at any stride here: the quadrature of their
  // exchange must converge (docs/simulator.md 6.9.1 measures a head, whose face is not).
  constexpr double kConvergedFraction = 0.05;  // 4 px against 2 px, of the 2 px shift
  const Scene scene = CornerScene(true);
  const std::vector<double> shift_mm = LeftWallShiftsMm(scene, {16, 8, 4, 2});
  const double reference = shift_mm.back();
  EXPECT_LT(std::abs(shift_mm[2] - reference), kConvergedFraction * reference);
  EXPECT_LT(std::abs(shift_mm[2] - reference), std::abs(shift_mm[0] - reference) + 0.05);
}

TEST(Multipath, OnARoughSurfaceTheBlocksConvergeToThePerPixelExchange) {
  // Bumps of 0.6 mm every 6 mm (2.6 px at 500 mm) tilt the pixels' normals by up to 32 deg, as
  // the suite's rough MR skin does (docs/correction.md 7.2). A block faces the way its pixels'
  // normals do on average; at 1 px the exchange is per pixel (every pixel an emitter and a
  // receiver with its own normal), the quadrature's limit. On this concave corner every facet
  // sees the other wall, so the mean normal and the facets agree on what is exchanged.
  constexpr double kConvergedFraction = 0.02;  // 2 px against 1 px
  // 16 px against 1 px: measured 1.6 % (7.04 against 6.92 mm); one centre pixel's normal per
  // block, before session 50: 8 %.
  constexpr double kCoarseFraction = 0.05;
  const Scene scene = CornerScene(true, 0.6);
  const std::vector<double> shift_mm = LeftWallShiftsMm(scene, {16, 8, 4, 2, 1});
  const double reference = shift_mm.back();
  EXPECT_LT(std::abs(shift_mm[3] - reference), kConvergedFraction * reference);
  EXPECT_LT(std::abs(shift_mm[0] - reference), kCoarseFraction * reference);
}

TEST(Multipath, ARoughConvexCornerExchangesAlmostNoLight) {
  // Its walls cannot see each other (every chord runs behind them) however their 0.6 mm bumps
  // tilt single pixels: the blocks' facing test, which stands in for visibility, reads the
  // surface's mean normal. One centre pixel's normal per block read 0.48 mm at 16 px and 0.88
  // at 8 px here (session 50), 0.001 and 0.003 with the block's mean normal.
  constexpr double kDarkMm = 0.05;
  const Scene scene = CornerScene(false, 0.6);
  const std::vector<double> shift_mm = LeftWallShiftsMm(scene, {16, 8});
  EXPECT_LT(shift_mm[0], kDarkMm);
  EXPECT_LT(shift_mm[1], kDarkMm);
}

TEST(Multipath, AConvexCornerExchangesNoLight) {
  const Scene scene = CornerScene(false);
  const RenderResult off = Render(scene, IdealWithMultipath(0.0));
  const RenderResult on = Render(scene, IdealWithMultipath(1.0));
  EXPECT_EQ(MeanBiasMm(on, off, -1), 0.0);
  EXPECT_EQ(MeanBiasMm(on, off, 1), 0.0);
}

// A 24 mm disc at 350 mm turned 45 degrees towards +x (so its pixels span ~17 mm of range and the
// 1 mm quantisation averages out), of `material`; with `board`, a bright 300 x 300 mm board
// beside it that faces both the disc and the camera (a concave corner, crease behind the disc).
Scene DiscBesideBoard(const Material& material, bool board) {
  Scene scene;
  const int disc_material = scene.AddMaterial(material);
  const double s = std::numbers::sqrt2 / 2.0;
  Tool tool;
  tool.name = "disc";
  tool.scene_from_tool = Rigid3d::Identity();
  tool.markers.push_back(
      {MarkerShape::kDisc, 24.0, {0.0, 0.0, 350.0}, {s, 0.0, -s}, disc_material});
  scene.AddTool(tool);
  if (board) {
    const int m = scene.AddMaterial(DiffuseMaterial(0.9));
    const Eigen::Quaterniond flip(Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitX()));
    const Eigen::Quaterniond turn(
        Eigen::AngleAxisd(std::numbers::pi / 4.0, Eigen::Vector3d::UnitY()));
    const Eigen::Vector3d crease(30.0, 0.0, 380.0);
    scene.AddObject("board", PlaneMesh(300.0, 300.0), m,
                    Rigid3d(turn * flip, crease + 150.0 * Eigen::Vector3d(s, 0.0, -s)));
  }
  return scene;
}

// Mean measured-minus-true range [mm] over the pixels whose centre ray hits the disc.
double DiscRangeErrorMm(const RenderResult& r) {
  double sum = 0.0;
  int count = 0;
  for (int v = 0; v < r.frame.range_mm.height(); ++v) {
    for (int u = 0; u < r.frame.range_mm.width(); ++u) {
      if (r.truth_marker(u, v) < 0 || r.frame.range_mm(u, v) >= kLowSignalCode) continue;
      sum += r.frame.range_mm(u, v) - r.truth_range_mm(u, v) - r.truth_bias_mm(u, v);
      ++count;
    }
  }
  EXPECT_GT(count, 100);
  return sum / std::max(count, 1);
}

TEST(Multipath, ARetroReflectorIgnoresABrightBoardBesideItWhileADiffusePatchDoesNot) {
  // A retro-reflector returns indirect light towards the board, not the camera: only its
  // diffuse base (rho 0.3 against ~10^3 of retro-reflection) adds a path. The tracking budget
  // for a marker centre is 0.2 mm (docs/tracking.md), so the board may move it by less.
  constexpr double kRetroToleranceMm = 0.2;
  // The same disc, diffuse, must read the board's light: mm-level in a concave corner.
  constexpr double kDiffuseMinShiftMm = 1.0;
  RenderOptions options = IdealWithMultipath(1.0);
  options.window = WindowAround(CentrePixel().x(), CentrePixel().y(), 320);
  const auto shift_mm = [&](const Material& material) {
    return DiscRangeErrorMm(Render(DiscBesideBoard(material, true), options)) -
           DiscRangeErrorMm(Render(DiscBesideBoard(material, false), options));
  };
  const double retro_mm = shift_mm(RetroReflectiveMaterial(RetroCurve::kNone));
  const double diffuse_mm = shift_mm(DiffuseMaterial(0.3));
  RecordProperty("retro_shift_mm", std::to_string(retro_mm));
  RecordProperty("diffuse_shift_mm", std::to_string(diffuse_mm));
  EXPECT_LT(std::abs(retro_mm), kRetroToleranceMm);
  EXPECT_GT(diffuse_mm, kDiffuseMinShiftMm);
}

TEST(Multipath, RejectsBadOptions) {
  EXPECT_THROW((MultipathOptions{-1.0, 16, 16}.Check()), PreconditionError);
  EXPECT_THROW((MultipathOptions{1.0, 0, 16}.Check()), PreconditionError);
}

}  // namespace
}  // namespace tofnav::sim
