// SPDX-License-Identifier: BSD-3-Clause
// AhatCamera validity: corners, the monotone rule at the fold, the radius option, bad entries.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "tofnav/core/require.hpp"
#include "tofnav/sensor/ahat_camera.hpp"

namespace tofnav {
namespace {

constexpr double kRangeMm = 500.0;
constexpr double kRoundTripTolPx = 0.01;       // brief: Project inverts Ray to 0.01 px
constexpr double kPrincipalPointTolPx = 1e-3;  // x, y are odd around it: interpolation exact

const AhatCalibration& DefaultCalibration() {
  static const AhatCalibration calibration = MakeSyntheticAhatCalibration();
  return calibration;
}

TEST(AhatCamera, CornersAreMaskedAndTheCentreIsValid) {
  const AhatCamera camera(DefaultCalibration());
  for (const auto& [u, v] : {std::pair{0, 0}, {511, 0}, {0, 511}, {511, 511}}) {
    EXPECT_FALSE(camera.IsValid(u, v)) << u << ", " << v;
    EXPECT_EQ(camera.PixelRay(u, v), Eigen::Vector3f::Zero());
    EXPECT_FALSE(camera.Ray(Eigen::Vector2d(u, v)).has_value());
  }
  EXPECT_TRUE(camera.IsValid(256, 256));
  EXPECT_NEAR(camera.PixelRay(256, 256).norm(), 1.0, 1e-6);
  EXPECT_FALSE(camera.IsValid(-1, 256));
  EXPECT_FALSE(camera.IsValid(256, 512));
}

TEST(AhatCamera, FoldIsMaskedByTheMonotoneRule) {
  SyntheticAhatOptions options;
  options.fold_radius_px = 200.0;  // inside the image along both axes
  const AhatCamera camera(MakeSyntheticAhatCalibration(options));
  int folded_valid = 0;
  int unfolded_invalid = 0;
  for (int v = 0; v < camera.height(); ++v) {
    for (int u = 0; u < camera.width(); ++u) {
      const double r_px = (Eigen::Vector2d(u, v) - options.principal_point_px).norm();
      // The walk stops at the first entry that moves back; the fold peak lies between two
      // entries, so one entry (< sqrt(2) px) past it may survive.
      folded_valid += (r_px > options.fold_radius_px + std::sqrt(2.0) && camera.IsValid(u, v));
      unfolded_invalid += (r_px < options.fold_radius_px && !camera.IsValid(u, v));
    }
  }
  EXPECT_EQ(folded_valid, 0);
  EXPECT_EQ(unfolded_invalid, 0);
  // A direction inside the field projects onto the unfolded branch, r = f * theta; one past the
  // fold angle (200 / 254 rad = 45.1 degrees) has no valid pixel.
  const auto direction = [](double theta_rad, double azimuth_rad) {
    return Eigen::Vector3d(std::sin(theta_rad) * std::cos(azimuth_rad),
                           std::sin(theta_rad) * std::sin(azimuth_rad), std::cos(theta_rad));
  };
  const std::optional<Eigen::Vector2d> inside = camera.Project(kRangeMm * direction(0.6, 0.8));
  ASSERT_TRUE(inside.has_value());
  EXPECT_NEAR((*inside - options.principal_point_px).norm(), 0.6 * options.focal_px,
              kRoundTripTolPx);
  EXPECT_FALSE(camera.Project(kRangeMm * direction(0.85, 0.8)).has_value());
  EXPECT_FALSE(camera.Project(Eigen::Vector3d(10.0, 0.0, 0.0)).has_value());  // z = 0
  EXPECT_FALSE(camera.Project(Eigen::Vector3d(0.0, 0.0, -kRangeMm)).has_value());
}

TEST(AhatCamera, ValidRadiusOptionTrimsTheRim) {
  AhatCameraOptions options;
  options.valid_radius_px = 150.0;
  const AhatCamera camera(DefaultCalibration(), options);
  const Eigen::Vector2d centre = camera.principal_point_px();
  EXPECT_TRUE(camera.IsValid(static_cast<int>(centre.x()) + 149, static_cast<int>(centre.y())));
  EXPECT_FALSE(camera.IsValid(static_cast<int>(centre.x()) + 152, static_cast<int>(centre.y())));
  EXPECT_FALSE(camera.Project(kRangeMm * Eigen::Vector3d(std::sin(0.7), 0.0, std::cos(0.7)))
                   .has_value());  // 0.7 rad = 178 px
}

TEST(AhatCamera, ZeroFilledAndNaNEntriesStopTheWalk) {
  AhatCalibration calibration = DefaultCalibration();
  calibration.uv2xy(100, 300) = Eigen::Vector2f::Zero();  // a failed API call, far from centre
  calibration.uv2xy(300, 100) = Eigen::Vector2f::Constant(std::nanf(""));
  const AhatCamera camera(calibration);
  // Still found where x = y = 0 is interpolated, not at the zero-filled entry.
  EXPECT_LT((camera.principal_point_px() - SyntheticAhatOptions{}.principal_point_px).norm(),
            kPrincipalPointTolPx);
  // The row walk (x) stops at the zero and the column walk (y) at the NaN: the entries beyond
  // them are lost along that line, the ones before stay.
  EXPECT_FALSE(camera.IsValid(100, 300));
  EXPECT_FALSE(camera.IsValid(99, 300));
  EXPECT_TRUE(camera.IsValid(101, 300));
  EXPECT_TRUE(camera.IsValid(100, 299));
  EXPECT_FALSE(camera.IsValid(300, 100));
  EXPECT_FALSE(camera.IsValid(300, 99));
  EXPECT_TRUE(camera.IsValid(300, 101));
  EXPECT_FALSE(camera.Ray(Eigen::Vector2d(100.5, 300.0)).has_value());
  EXPECT_TRUE(camera.Ray(Eigen::Vector2d(101.5, 300.0)).has_value());
}

TEST(AhatCameraOptions, CheckNamesTheBadField) {
  EXPECT_NO_THROW(AhatCameraOptions{}.Check());
  for (const double c : {1.0, -0.1, std::nan("")}) {
    EXPECT_THAT(
        [&] { AhatCameraOptions{.pixel_centre_offset_px = c}.Check(); },
        testing::ThrowsMessage<PreconditionError>(testing::HasSubstr("pixel_centre_offset_px")));
  }
  EXPECT_THAT([] { AhatCameraOptions{.valid_radius_px = -1.0}.Check(); },
              testing::ThrowsMessage<PreconditionError>(testing::HasSubstr("valid_radius_px")));
  const AhatCalibration& calibration = DefaultCalibration();
  EXPECT_THROW(AhatCamera(calibration, {.pixel_centre_offset_px = 1.5}), PreconditionError);
  AhatCalibration bad = calibration;
  bad.sample_offset_px = 1.0;
  EXPECT_THROW(AhatCamera{bad}, PreconditionError);
  EXPECT_THROW(AhatCamera{AhatCalibration{}}, PreconditionError);
  bad = calibration;
  for (Eigen::Vector2f& xy : bad.uv2xy.pixels()) xy = Eigen::Vector2f::Constant(std::nanf(""));
  EXPECT_THROW(AhatCamera{bad}, PreconditionError);
}

}  // namespace
}  // namespace tofnav
