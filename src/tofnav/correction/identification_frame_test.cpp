// SPDX-License-Identifier: BSD-3-Clause
// PrepareIdentificationFrame on an analytic frame: a sticker on the skin enters Eq. (5-6), a
// tool's sphere seen against the skin does not.
#include "tofnav/correction/identification_frame.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <optional>

#include "correction_test_scenes.hpp"

namespace tofnav {
namespace {

constexpr double kBallRadiusMm = 5.75;  // an 11.5 mm tool sphere

// Nearest hit of `ray` (from the origin) with the sphere, or nothing.
std::optional<double> HitSphere(const Eigen::Vector3d& ray, const Eigen::Vector3d& centre,
                                double radius) {
  const double b = ray.dot(centre), c = centre.squaredNorm() - radius * radius;
  const double disc = b * b - c;
  if (disc < 0.0) return std::nullopt;
  return b - std::sqrt(disc);
}

struct Scene {
  Eigen::Vector3d head_centre{0.0, 0.0, 500.0};
  Eigen::Vector3d sticker_centre, ball_centre;
  Scene() {
    // The sticker 25 mm left of the apex, on the skin; the ball 25 mm right, resting on it.
    const Eigen::Vector3d left = Eigen::Vector3d(-25.0, 0.0, 0.0);
    const Eigen::Vector3d on_skin =
        head_centre +
        testing::kHeadRadiusMm * (left - Eigen::Vector3d(0.0, 0.0, 87.0)).normalized();
    sticker_centre = on_skin;
    const Eigen::Vector3d right_dir = (-left - Eigen::Vector3d(0.0, 0.0, 87.0)).normalized();
    ball_centre = head_centre + (testing::kHeadRadiusMm + kBallRadiusMm) * right_dir;
  }
};

AhatFrame MakeFrame(const Scene& s) {
  AhatFrame frame = testing::SyntheticFrame(
      [&](int, int, const Eigen::Vector3d& ray) {
        const auto ball = HitSphere(ray, s.ball_centre, kBallRadiusMm);
        const auto head = HitSphere(ray, s.head_centre, testing::kHeadRadiusMm);
        if (ball && (!head || *ball < *head)) return *ball;
        return head ? *head : 0.0;
      },
      [](double d, int, int) { return d; }, 150);
  const AhatCamera& camera = testing::CorrectionCamera();
  for (int v = 0; v < camera.height(); ++v) {
    for (int u = 0; u < camera.width(); ++u) {
      if (frame.range_mm(u, v) == 0) continue;
      const Eigen::Vector3d p = camera.PixelRay(u, v).cast<double>() * frame.range_mm(u, v);
      const bool sticker = (p - s.sticker_centre).norm() < 6.0;
      const bool ball = (p - s.ball_centre).norm() < kBallRadiusMm + 1.0;
      if (sticker || ball) frame.ab(u, v) = 3000;
    }
  }
  return frame;
}

TEST(PrepareIdentificationFrame, LeavesOutASphereSeenAgainstTheSkin) {
  // The sticker's 12 mm disc bends like the 90 mm head (k = 1 / 180 per mm), the ball like
  // itself (k = 1 / 11.5 per mm); the limit (1 / 25 per mm) lies between, with the 1 mm range
  // rounding's noise on 48 points well below either margin.
  const Scene scene;
  const AhatFrame frame = MakeFrame(scene);
  IdentificationSampling sampling;
  sampling.multipath.enabled = false;
  sampling.segmentation.head_region.enabled = false;
  const MarkerRangeModel exact;  // the ranges are exact (f_rf = 0)
  const IdentificationFrame kept =
      PrepareIdentificationFrame(frame, testing::CorrectionCamera(), exact, 0, sampling);
  EXPECT_EQ(kept.curved_markers, 1);
  ASSERT_EQ(kept.markers.size(), 1u);
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : kept.markers[0].marker_points) centre += p;
  centre /= static_cast<double>(kept.markers[0].marker_points.size());
  EXPECT_LT((centre - scene.sticker_centre).norm(), 3.0);  // the sticker, not the ball

  // With no limit to speak of, both markers enter.
  sampling.max_sticker_curvature_per_mm = 1.0;
  const IdentificationFrame both =
      PrepareIdentificationFrame(frame, testing::CorrectionCamera(), exact, 0, sampling);
  EXPECT_EQ(both.curved_markers, 0);
  EXPECT_EQ(both.markers.size(), 2u);
}

// How far the sticker's points lie behind the skin, on average [mm] (+ = read long).
double MeanDepthBehindSkin(const Scene& scene, const IdentificationFrame& frame) {
  double sum = 0.0;
  int count = 0;
  for (const MarkerPatch& patch : frame.markers) {
    for (const Eigen::Vector3d& p : patch.marker_points) {
      if ((p - scene.sticker_centre).norm() > 10.0) continue;  // the sticker's, not the ball's
      sum += testing::kHeadRadiusMm - (p - scene.head_centre).norm();
      ++count;
    }
  }
  return count > 0 ? sum / count : 1e9;
}

TEST(PrepareIdentificationFrame, TakesAStickersRangeFromItsCoreNotItsMixedRim) {
  // The sticker's outer 2 mm is a rim of mixed pixels: dimmer (1500 counts against the core's
  // 3000, under 0.7 of the peak) and 3 mm long, the skin's own delayed light mixed into the
  // tape's. The core alone lies on the skin (1 mm range rounding averaged over its points:
  // 0.3 mm); with the rim, the points read long by about 3 mm times the rim's share of them.
  const Scene scene;
  AhatFrame frame = MakeFrame(scene);
  const AhatCamera& camera = testing::CorrectionCamera();
  for (int v = 0; v < camera.height(); ++v) {
    for (int u = 0; u < camera.width(); ++u) {
      if (frame.range_mm(u, v) == 0) continue;
      const Eigen::Vector3d p = camera.PixelRay(u, v).cast<double>() * frame.range_mm(u, v);
      const double r = (p - scene.sticker_centre).norm();
      if (r >= 4.0 && r < 6.0) {
        frame.ab(u, v) = 1500;
        frame.range_mm(u, v) = static_cast<std::uint16_t>(frame.range_mm(u, v) + 3);
      }
    }
  }
  IdentificationSampling sampling;
  sampling.multipath.enabled = false;
  sampling.segmentation.head_region.enabled = false;
  const MarkerRangeModel exact;
  const double core =
      MeanDepthBehindSkin(scene, PrepareIdentificationFrame(frame, camera, exact, 0, sampling));
  EXPECT_NEAR(core, 0.0, 0.3);
  sampling.marker_core_ab_fraction = 0.0;  // every pixel of the sticker
  const double all =
      MeanDepthBehindSkin(scene, PrepareIdentificationFrame(frame, camera, exact, 0, sampling));
  EXPECT_GT(all, 1.0);
}

TEST(PrepareIdentificationFrame, RefusesANonPositiveCurvatureLimit) {
  IdentificationSampling sampling;
  sampling.max_sticker_curvature_per_mm = 0.0;
  EXPECT_THROW(sampling.Check(), std::invalid_argument);
  sampling = {};
  sampling.marker_core_ab_fraction = 1.5;
  EXPECT_THROW(sampling.Check(), std::invalid_argument);
}

}  // namespace
}  // namespace tofnav
