// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/fusion/pixel_lookup.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "tofnav/fusion/fusion_test_scenes.hpp"
#include "tofnav/sensor/ahat_calibration.hpp"

namespace tofnav {
namespace {

// The lookup is piecewise linear over pixel triangles, then bilinear between nodes about 1 px
// apart; both are exact for an affine map, and the fisheye's curvature over 1 px is far smaller.
constexpr double kRoundTripTolPx = 0.01;
// Against AhatCamera::Project (bilinear on the unit plane): the two interpolants differ at second
// order within a pixel.
constexpr double kVsCameraTolPx = 0.02;

class PixelLookupTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    camera_ = new AhatCamera(MakeSyntheticAhatCalibration());
    lookup_ = new PixelLookup(*camera_);
  }
  static void TearDownTestSuite() {
    delete lookup_;
    delete camera_;
  }
  static const AhatCamera* camera_;
  static const PixelLookup* lookup_;
};
const AhatCamera* PixelLookupTest::camera_ = nullptr;
const PixelLookup* PixelLookupTest::lookup_ = nullptr;

TEST_F(PixelLookupTest, PixelRaysProjectBackToTheirPixel) {
  int checked = 0;
  for (int v = 1; v + 1 < camera_->height(); v += 5) {
    for (int u = 1; u + 1 < camera_->width(); u += 5) {
      if (!camera_->IsValid(u - 1, v - 1) || !camera_->IsValid(u + 1, v + 1) ||
          !camera_->IsValid(u - 1, v + 1) || !camera_->IsValid(u + 1, v - 1)) {
        continue;
      }
      const Eigen::Vector3d point = 400.0 * camera_->PixelRay(u, v).cast<double>();
      const std::optional<Eigen::Vector2d> pixel = lookup_->Project(point);
      ASSERT_TRUE(pixel.has_value()) << u << ", " << v;
      EXPECT_NEAR(pixel->x(), u, kRoundTripTolPx);
      EXPECT_NEAR(pixel->y(), v, kRoundTripTolPx);
      ++checked;
    }
  }
  EXPECT_GT(checked, 7000);  // most of the 118 degree field
}

TEST_F(PixelLookupTest, AgreesWithCameraProjectBetweenPixels) {
  // Directions up to 55 degrees off axis (r = 244 px), short of the synthetic table's fold at
  // 262 px, where the two interpolants part by up to 0.05 px.
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int compared = 0;
  for (int i = 0; i < 300; ++i) {
    const double theta = 0.96 * unit(rng);
    const double phi = 2.0 * std::numbers::pi * unit(rng);
    const Eigen::Vector3d direction(std::sin(theta) * std::cos(phi),
                                    std::sin(theta) * std::sin(phi), std::cos(theta));
    const Eigen::Vector3d point = 350.0 * direction;
    const std::optional<Eigen::Vector2d> expected = camera_->Project(point);
    const std::optional<Eigen::Vector2d> actual = lookup_->Project(point);
    ASSERT_TRUE(expected.has_value() && actual.has_value()) << point.transpose();
    EXPECT_LT((*actual - *expected).norm(), kVsCameraTolPx) << point.transpose();
    ++compared;
  }
  EXPECT_EQ(compared, 300);
}

TEST_F(PixelLookupTest, RejectsPointsNoPixelSees) {
  EXPECT_FALSE(lookup_->Project({0.0, 0.0, -100.0}).has_value());   // behind
  EXPECT_FALSE(lookup_->Project({1000.0, 0.0, 10.0}).has_value());  // 89 degrees off axis
  EXPECT_FALSE(lookup_->Project({0.0, 0.0, 0.0}).has_value());      // the optical centre
  EXPECT_TRUE(lookup_->Project({0.0, 0.0, 100.0}).has_value());
}

TEST(PixelLookup, WorksForOtherTableSizes) {
  const AhatCamera camera(SmallFisheyeCalibration(64));
  const PixelLookup lookup(camera, 0.5);
  const std::optional<Eigen::Vector2d> pixel =
      lookup.Project(250.0 * camera.PixelRay(40, 21).cast<double>());
  ASSERT_TRUE(pixel.has_value());
  EXPECT_NEAR(pixel->x(), 40.0, kRoundTripTolPx);
  EXPECT_NEAR(pixel->y(), 21.0, kRoundTripTolPx);
  EXPECT_THROW(PixelLookup(camera, 0.0), PreconditionError);
}

}  // namespace
}  // namespace tofnav
