// SPDX-License-Identifier: BSD-3-Clause
// MarkerVoidTest on hand-painted frames: bright, hidden, covered, void and unjudgeable places.
#include "tofnav/markers/marker_void.hpp"

#include <gtest/gtest.h>

#include <stdexcept>

#include "marker_test_scenes.hpp"

namespace tofnav {
namespace {

using testing::TestCamera;

constexpr double kDiameterMm = 10.0;
constexpr std::uint16_t kBackgroundRangeMm = 900;  // a far wall, every pixel
constexpr std::uint16_t kDarkAb = 60;              // skin or wall: far below a marker's AB

AhatFrame FarWall() {
  AhatFrame frame;
  frame.range_mm = Image<std::uint16_t>(kAhatWidth, kAhatHeight, kBackgroundRangeMm);
  frame.ab = Image<std::uint16_t>(kAhatWidth, kAhatHeight, kDarkAb);
  return frame;
}

// Paints a disc of `radius_px` around the projection of `point` with a range and an AB.
void Paint(AhatFrame& frame, const Eigen::Vector3d& point, double radius_px, std::uint16_t range_mm,
           std::uint16_t ab) {
  const Eigen::Vector2d c = *TestCamera().Project(point);
  for (int v = 0; v < kAhatHeight; ++v) {
    for (int u = 0; u < kAhatWidth; ++u) {
      if ((Eigen::Vector2d(u, v) - c).norm() > radius_px) continue;
      frame.range_mm(u, v) = range_mm;
      frame.ab(u, v) = ab;
    }
  }
}

TEST(MarkerVoidTest, AMarkerInTheAirBeforeAFarWallIsVoidAndNothingElseIs) {
  const Eigen::Vector3d place(20.0, -10.0, 500.0);  // 400 mm in front of the wall
  AhatFrame frame = FarWall();
  EXPECT_TRUE(MarkerVoidTest(frame, TestCamera()).IsVoid(place, kDiameterMm));

  // A marker there, even one the detector dropped, is bright in part of its disc.
  AhatFrame bright = FarWall();
  Paint(bright, place, 1.5, 500, 20000);
  EXPECT_FALSE(MarkerVoidTest(bright, TestCamera()).IsVoid(place, kDiameterMm));

  // A hand in front of it hides it: the images cannot say it is missing.
  AhatFrame hidden = FarWall();
  Paint(hidden, place, 12.0, 380, kDarkAb);
  EXPECT_FALSE(MarkerVoidTest(hidden, TestCamera()).IsVoid(place, kDiameterMm));

  // A drop or its own plate lying on it (a dark surface a few mm behind its centre): covered.
  AhatFrame covered = FarWall();
  Paint(covered, place, 12.0, 508, kDarkAb);
  EXPECT_FALSE(MarkerVoidTest(covered, TestCamera()).IsVoid(place, kDiameterMm));

  // No valid range around it (a saturated or invalid patch): the images cannot tell.
  AhatFrame invalid = FarWall();
  Paint(invalid, place, 12.0, 0, kDarkAb);
  EXPECT_FALSE(MarkerVoidTest(invalid, TestCamera()).IsVoid(place, kDiameterMm));

  // Behind the camera, or with its disc across the image's edge: not judged.
  EXPECT_FALSE(MarkerVoidTest(frame, TestCamera()).IsVoid({0.0, 0.0, -500.0}, kDiameterMm));
  const Eigen::Vector3d edge = TestCamera().PointFromRange(1, kAhatHeight / 2, 500.0);
  EXPECT_FALSE(MarkerVoidTest(frame, TestCamera()).IsVoid(edge, kDiameterMm));
}

TEST(MarkerVoidTest, TheDetectorsThresholdSaysWhatIsBrightAndBadOptionsThrow) {
  const Eigen::Vector3d place(-30.0, 25.0, 450.0);
  AhatFrame frame = FarWall();
  Paint(frame, place, 2.0, 450, 3000);  // bright to the default threshold, not to a raised one
  EXPECT_FALSE(MarkerVoidTest(frame, TestCamera()).IsVoid(place, kDiameterMm));
  MarkerDetectionResult detected;
  detected.ab_threshold = 5000.0;
  EXPECT_TRUE(
      MarkerVoidTest(frame, TestCamera(), detected.ab_threshold).IsVoid(place, kDiameterMm));
  MarkerVoidOptions bad;
  bad.behind_margin_mm = 0.0;
  EXPECT_THROW(MarkerVoidTest(frame, TestCamera(), bad), std::invalid_argument);
  bad = {};
  bad.min_valid_fraction = 1.5;
  EXPECT_THROW(MarkerVoidTest(frame, TestCamera(), bad), std::invalid_argument);
}

}  // namespace
}  // namespace tofnav
