// SPDX-License-Identifier: BSD-3-Clause
// Checked fusion against simulated truth: a frame with a wrong pose is rejected, a small offset
// refined back to the truth, and a hand passing over the forehead does not change it.
#include "tofnav/fusion/model_check.hpp"

#include <gtest/gtest.h>

#include <numbers>
#include <random>

#include "tofnav/core/require.hpp"
#include "tofnav/fusion/fusion_test_scenes.hpp"
#include "tofnav/fusion/marching_cubes.hpp"
#include "tofnav/fusion/mesh_components.hpp"
#include "tofnav/fusion/surface_distance.hpp"

namespace tofnav {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr int kFrames = 40;
constexpr double kNoiseMm = 1.0;  // range noise sigma, as the AHAT on skin (docs/simulator.md)
const Eigen::Vector3d kForward(0.2, -1.0, 0.3);  // the side of the head the views see

// The bound: one frame with a 5 deg pose error changes the fused surface by at most
// 0.05 mm median (against fusing without that frame).
constexpr double kBadFrameChangeTolMm = 0.05;
// A refined pose puts the frame's points on the true surface within the alignment's noise: 1 mm
// range noise over ~1400 points leaves a few hundredths of a mm, the model's own error (~0.07 mm
// median) adds to it.
constexpr double kRefinedTolMm = 0.1;
constexpr double kOffsetMinMm = 0.3;  // the offset is large enough to show
// The hand must not move the forehead: its median error with the hand stays within this of the
// error without it (the noise of two fusions of different frames is ~0.01 mm).
constexpr double kHandChangeTolMm = 0.05;

const AhatCamera& Camera() {
  static const AhatCamera camera(SmallFisheyeCalibration(256));
  return camera;
}

// The 256 px test camera has a quarter of the AHAT's pixels: sample every pixel, so that the
// alignment has as many points as the default stride gives on the 512 px AHAT.
ModelCheckOptions CheckOptions() {
  ModelCheckOptions options;
  options.pixel_stride = 1;
  options.refine = true;  // the alignment is what these tests check
  return options;
}

TsdfOptions Options() {
  TsdfOptions options;  // 1 mm voxels, truncation 4 voxels
  return options;
}

std::vector<Rigid3d> Poses(const EllipsoidHead& head) {
  return FrontPoses(head.centre_in_tool, kForward, 0.6, kFrames, 3);
}

// Median |distance| from the vertices of `a` to the surface `b` [mm].
double MedianDistance(const TriangleMesh& a, const TriangleMesh& b) {
  const SurfaceDistance distance(b);
  std::vector<double> d;
  for (const Eigen::Vector3d& v : a.vertices) {
    if (const auto c = distance.Closest(v, 10.0)) d.push_back(c->distance_mm);
  }
  return MedianAbs(d);
}

TEST(IntegrateChecked, AFrameWithAFiveDegreePoseErrorLeavesTheSurfaceUnchanged) {
#ifdef TOFNAV_SANITIZED
  GTEST_SKIP() << "minutes of fusion under the sanitizers; the -Werror pass runs it";
#endif
  const EllipsoidHead head;
  const std::vector<Rigid3d> poses = Poses(head);
  constexpr int kBad = 25;
  const Rigid3d error(Eigen::Quaterniond(Eigen::AngleAxisd(5.0 * kDeg, Eigen::Vector3d::UnitX())),
                      Eigen::Vector3d::Zero());
  const ModelCheckOptions options = CheckOptions();
  TriangleMesh meshes[3];  // checked with the bad frame, checked without it, unchecked with it
  for (int run = 0; run < 3; ++run) {
    TsdfVolume volume(Options(), Camera());
    std::mt19937_64 rng(11);
    ModelCheckOptions run_options = options;
    run_options.enabled = run != 2;
    for (int i = 0; i < kFrames; ++i) {
      const Rigid3d& truth = poses[static_cast<std::size_t>(i)];
      const Image<float> range = head.Render(Camera(), truth, kNoiseMm, rng);
      if (i == kBad && run == 1) continue;
      const Rigid3d tracked = i == kBad ? error * truth : truth;
      const CheckedIntegration r =
          IntegrateChecked(volume, range, Camera(), tracked, {}, run_options);
      if (i == kBad && run == 0) {
        EXPECT_FALSE(r.fused) << ToString(r.check.verdict);
      }
    }
    meshes[run] = LargestConnectedComponent(ExtractIsoSurface(volume));
  }
  const double change = MedianDistance(meshes[0], meshes[1]);
  const double unchecked_change = MedianDistance(meshes[2], meshes[1]);
  RecordProperty("change_mm", std::to_string(change));
  RecordProperty("unchecked_change_mm", std::to_string(unchecked_change));
  EXPECT_LE(change, kBadFrameChangeTolMm);
}

// Median |distance| of the frame's points posed by `pose` to the true head surface [mm].
double SurfaceErrorMm(const EllipsoidHead& head, const Image<float>& range, const Rigid3d& pose) {
  std::vector<double> d;
  for (int v = 0; v < range.height(); ++v) {
    for (int u = 0; u < range.width(); ++u) {
      if (range(u, v) > 0.0f)
        d.push_back(head.DistanceMm(pose * Camera().PointFromRange(u, v, range(u, v))));
    }
  }
  return MedianAbs(d);
}

TEST(CheckFrameAgainstModel, RefinesASmallOffsetBackToTheTruth) {
  const EllipsoidHead head;
  const std::vector<Rigid3d> poses = Poses(head);
  TsdfVolume volume(Options(), Camera());
  std::mt19937_64 rng(5);
  for (int i = 0; i + 1 < kFrames; ++i) {
    volume.Integrate(head.Render(Camera(), poses[static_cast<std::size_t>(i)], kNoiseMm, rng),
                     poses[static_cast<std::size_t>(i)]);
  }
  const Rigid3d& truth = poses.back();
  const Image<float> range = head.Render(Camera(), truth, kNoiseMm, rng);
  // 0.8 mm and 0.4 deg off: within the bound of 2 mm / 1 deg.
  const Rigid3d offset(Eigen::Quaterniond(Eigen::AngleAxisd(0.4 * kDeg, Eigen::Vector3d::UnitZ())),
                       Eigen::Vector3d(0.5, -0.4, 0.5));
  const ModelCheckResult r =
      CheckFrameAgainstModel(volume, range, Camera(), offset * truth, CheckOptions());
  ASSERT_EQ(r.verdict, ModelVerdict::kRefined);
  EXPECT_LT(r.median_residual_after_mm, r.median_residual_mm);
  // The error that matters for fusion: how far from the true surface the frame's (noise-free)
  // points land. Sliding along the surface is not observable and does not matter.
  const Image<float> clean = head.Render(Camera(), truth, 0.0, rng);
  EXPECT_LE(SurfaceErrorMm(head, clean, r.tool_from_ahat), kRefinedTolMm);
  EXPECT_GT(SurfaceErrorMm(head, clean, offset * truth), kOffsetMinMm);
  // The true pose stays on the surface.
  const ModelCheckResult same =
      CheckFrameAgainstModel(volume, range, Camera(), truth, CheckOptions());
  EXPECT_TRUE(same.verdict == ModelVerdict::kAccepted || same.verdict == ModelVerdict::kRefined);
  EXPECT_LE(SurfaceErrorMm(head, clean, same.tool_from_ahat), kRefinedTolMm);
}

// Range to the nearer of the head and a hand (a sphere of 40 mm radius) [mm].
Image<float> WithHand(Image<float> range, const Image<float>& hand) {
  for (std::size_t i = 0; i < range.size(); ++i) {
    const float h = hand.data()[i];
    if (h > 0.0f && (range.data()[i] <= 0.0f || h < range.data()[i])) range.data()[i] = h;
  }
  return range;
}

TEST(IntegrateChecked, AHandPassingOverTheForeheadDoesNotChangeIt) {
#ifdef TOFNAV_SANITIZED
  GTEST_SKIP() << "minutes of fusion under the sanitizers; the -Werror pass runs it";
#endif
  const EllipsoidHead head;
  const std::vector<Rigid3d> poses = FrontPoses(head.centre_in_tool, kForward, 0.6, 60, 9);
  // The forehead: the head's surface point along kForward, and the surface within 40 mm of it.
  const Eigen::Vector3d f = kForward.normalized();
  double t = 50.0;  // on the ray centre + t f, to the surface by Newton on the distance
  for (int k = 0; k < 20; ++k) t -= head.DistanceMm(head.centre_in_tool + t * f);
  const Eigen::Vector3d forehead = head.centre_in_tool + t * f;
  const Eigen::Vector3d side = f.unitOrthogonal();
  constexpr double kHandRadiusMm = 40.0, kGapMm = 4.0;  // the hand passes 4 mm above the skin
  constexpr int kHandFirst = 20, kHandFrames = 30;
  double errors[3];  // forehead median error without the hand, with it, with it unchecked
  for (int run = 0; run < 3; ++run) {
    ModelCheckOptions options = CheckOptions();
    options.enabled = run != 2;
    TsdfVolume volume(Options(), Camera());
    std::mt19937_64 rng(21);
    for (int i = 0; i < 60; ++i) {
      const Rigid3d& pose = poses[static_cast<std::size_t>(i)];
      Image<float> range = head.Render(Camera(), pose, kNoiseMm, rng);
      if (run >= 1 && i >= kHandFirst && i < kHandFirst + kHandFrames) {
        const double s = -60.0 + 120.0 * (i - kHandFirst) / (kHandFrames - 1);  // across
        const Eigen::Vector3d centre = forehead + (kHandRadiusMm + kGapMm) * f + s * side;
        range =
            WithHand(range, RenderSphere(Camera(), pose, centre, kHandRadiusMm, kNoiseMm, &rng));
      }
      IntegrateChecked(volume, range, Camera(), pose, {}, options);
    }
    const TriangleMesh mesh = LargestConnectedComponent(ExtractIsoSurface(volume));
    std::vector<double> e;
    for (const Eigen::Vector3d& v : mesh.vertices) {
      if ((v - forehead).norm() <= 40.0) e.push_back(head.DistanceMm(v));
    }
    ASSERT_GT(e.size(), 1000u);
    errors[run] = MedianAbs(e);
  }
  RecordProperty("forehead_error_mm", std::to_string(errors[0]));
  RecordProperty("forehead_error_with_hand_mm", std::to_string(errors[1]));
  RecordProperty("forehead_error_with_hand_unchecked_mm", std::to_string(errors[2]));
  EXPECT_LE(std::abs(errors[1] - errors[0]), kHandChangeTolMm);
}

TEST(ModelCheckOptions, CheckNamesTheBadField) {
  ModelCheckOptions options;
  EXPECT_NO_THROW(options.Check());
  options.pixel_stride = 0;
  EXPECT_THROW(options.Check(), PreconditionError);
  options = {};
  options.min_inlier_fraction = 1.5;
  EXPECT_THROW(options.Check(), PreconditionError);
}

}  // namespace
}  // namespace tofnav
