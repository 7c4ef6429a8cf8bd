// SPDX-License-Identifier: BSD-3-Clause
// The automatic head region on an analytic scene: a head on a board, a tool plate beside it.
#include "tofnav/correction/head_region.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "correction_test_scenes.hpp"

namespace tofnav {
namespace {

using testing::CorrectionCamera;

// A sphere (the head, 90 mm) sunk 30 mm into a tilted board (600 mm away), and a 70 x 50 mm
// plate floating 40 mm in front of the board beside the head. Labels: 1 head, 2 board, 3 plate.
constexpr double kHeadRadiusMm = 90.0;
const Eigen::Vector3d kHeadCentre(0.0, 0.0, 540.0);
const Eigen::Vector3d kPlateCentre(150.0, -20.0, 520.0);

double SphereRange(const Eigen::Vector3d& ray) {
  const double b = ray.dot(kHeadCentre);
  const double disc = b * b - kHeadCentre.squaredNorm() + kHeadRadiusMm * kHeadRadiusMm;
  return disc < 0.0 ? 0.0 : b - std::sqrt(disc);
}

Image<float> SceneRange(Image<std::uint8_t>& labels) {
  const AhatCamera& camera = CorrectionCamera();
  const testing::TestPlane board = testing::TiltedPlane(600.0, 0.25);
  const testing::TestPlane plate{Eigen::Vector3d::UnitZ(), kPlateCentre.z()};
  Image<float> range(camera.width(), camera.height());
  labels = Image<std::uint8_t>(camera.width(), camera.height());
  for (int v = 0; v < camera.height(); ++v) {
    for (int u = 0; u < camera.width(); ++u) {
      if (!camera.IsValid(u, v)) continue;
      const Eigen::Vector3d ray = camera.PixelRay(u, v).cast<double>();
      double best = board.Range(ray);
      std::uint8_t label = 2;
      const double s = SphereRange(ray);
      if (s > 0.0 && s < best) best = s, label = 1;
      const Eigen::Vector3d p = ray * plate.Range(ray) - kPlateCentre;
      if (std::abs(p.x()) <= 35.0 && std::abs(p.y()) <= 25.0 && plate.Range(ray) < best) {
        best = plate.Range(ray), label = 3;
      }
      range(u, v) = static_cast<float>(best);
      labels(u, v) = label;
    }
  }
  return range;
}

TEST(SelectHeadRegion, KeepsTheHeadAndDropsTheBoardAndThePlate) {
  Image<std::uint8_t> labels;
  const Image<float> range = SceneRange(labels);
  const HeadRegion region = SelectHeadRegion(range, CorrectionCamera());
  EXPECT_EQ(region.planes_removed, 1);  // the board (the plate is below the area gate)
  int head = 0, head_kept = 0, other_kept = 0, plate_kept = 0;
  for (int v = 0; v < range.height(); ++v) {
    for (int u = 0; u < range.width(); ++u) {
      if (labels(u, v) == 1) ++head, head_kept += region.mask(u, v);
      if (labels(u, v) > 1) other_kept += region.mask(u, v);
      if (labels(u, v) == 3) plate_kept += region.mask(u, v);
    }
  }
  // The head loses only its band within the plane tolerance of the board (the crease).
  constexpr double kMinHeadKept = 0.95;
  constexpr int kMaxLeakPx = 0;  // noise-free: nothing of the board or plate is left
  EXPECT_GT(head_kept, kMinHeadKept * head) << head_kept << " of " << head;
  EXPECT_LE(other_kept, kMaxLeakPx);
  EXPECT_EQ(plate_kept, 0);
}

TEST(SelectHeadRegion, DisabledKeepsEveryRangePixel) {
  Image<std::uint8_t> labels;
  const Image<float> range = SceneRange(labels);
  HeadRegionOptions options;
  options.enabled = false;
  const HeadRegion region = SelectHeadRegion(range, CorrectionCamera(), options);
  int valid = 0;
  for (int v = 0; v < range.height(); ++v) {
    for (int u = 0; u < range.width(); ++u) {
      valid += range(u, v) > 0.0f && CorrectionCamera().IsValid(u, v) ? 1 : 0;
    }
  }
  EXPECT_EQ(region.pixels, valid);
}

TEST(SelectHeadRegion, RejectsBadOptionsAndSizes) {
  HeadRegionOptions options;
  options.min_flat_ratio = 1.5;
  EXPECT_THROW(SelectHeadRegion(Image<float>(512, 512), CorrectionCamera(), options),
               std::invalid_argument);
  EXPECT_THROW(SelectHeadRegion(Image<float>(16, 16), CorrectionCamera()), std::invalid_argument);
}

}  // namespace
}  // namespace tofnav
