// SPDX-License-Identifier: BSD-3-Clause
#include "tofnav/sensor/ahat_calibration.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "matchers.hpp"
#include "tofnav/core/require.hpp"
#include "tofnav/sensor/ahat_camera.hpp"
#include "tofnav/sensor/ahat_frame.hpp"

namespace tofnav {
namespace {

constexpr double kFloatTol = 1e-6;  // unit-plane entries are stored as float
// Map entries fall between pixel centres, where Ray interpolates tan(theta) bilinearly: about
// 6e-6 rad at the pinhole's 55 degree corners.
constexpr double kInterpolatedRayTolRad = 1.5e-5;
constexpr double kExtrinsicsTolMm = 0.5;   // brief: rounded section 10 values
constexpr double kAxisTol = 2e-3;          // rounded rotation, 3 decimals quoted
constexpr double kOrthonormalTol = 1e-12;  // SVD projection

/// Independent evaluation of docs/ahat.md section 11 for entry (i, j) (equidistant with fold).
Eigen::Vector2d ExpectedEntry(int i, int j, const SyntheticAhatOptions& options) {
  const Eigen::Vector2d offset =
      Eigen::Vector2d(i + options.sample_offset_px - 0.5, j + options.sample_offset_px - 0.5) -
      options.principal_point_px;
  const double r = offset.norm();
  const double theta = r <= options.fold_radius_px
                           ? r / options.focal_px
                           : (2.0 * options.fold_radius_px - r) / options.focal_px;
  return std::tan(theta) / r * offset;
}

SyntheticAhatOptions TypicalOptions(double sample_offset_px) {
  SyntheticAhatOptions options;
  options.sample_offset_px = sample_offset_px;
  options.rig_from_ahat = TypicalRigFromAhat();
  return options;
}

// Shared fixtures: a table and a camera take ~0.2 s each unoptimised.
const AhatCalibration& TypicalCalibration() {
  static const AhatCalibration calibration = MakeSyntheticAhatCalibration(TypicalOptions(0.5));
  return calibration;
}

TEST(SyntheticAhatCalibration, TableFollowsTheModelForBothSampleOffsets) {
  const AhatCalibration integer = MakeSyntheticAhatCalibration(TypicalOptions(0.0));
  for (const AhatCalibration* calibration : {&integer, &TypicalCalibration()}) {
    const SyntheticAhatOptions options = TypicalOptions(calibration->sample_offset_px);
    ASSERT_EQ(calibration->uv2xy.width(), kAhatWidth);
    ASSERT_EQ(calibration->uv2xy.height(), kAhatHeight);
    for (const auto& [i, j] : {std::pair{300, 200}, {10, 256}, {0, 0}, {511, 511}, {252, 253}}) {
      const Eigen::Vector2d expected = ExpectedEntry(i, j, options);
      EXPECT_NEAR(calibration->uv2xy(i, j).x(), expected.x(), kFloatTol * (1 + expected.norm()));
      EXPECT_NEAR(calibration->uv2xy(i, j).y(), expected.y(), kFloatTol * (1 + expected.norm()));
    }
  }
  EXPECT_EQ(integer.sample_offset_px, 0.0);
  EXPECT_EQ(TypicalCalibration().sample_offset_px, 0.5);
}

TEST(SyntheticAhatCalibration, StoresScalarsAndExtrinsics) {
  const AhatCalibration& calibration = TypicalCalibration();
  EXPECT_EQ(calibration.scale, 1000.0);
  EXPECT_EQ(calibration.alias_mm, 1055.0);
  EXPECT_EQ(calibration.pinhole_fx_fy_cx_cy, Eigen::Vector4d(254.0, 254.0, 255.5, 255.5));
  EXPECT_THAT(calibration.rig_from_ahat, RigidNear(TypicalRigFromAhat(), 0.0, 0.0));
}

TEST(SyntheticAhatCalibration, UndistortMapSeesThePinholeRays) {
  const AhatCalibration& calibration = TypicalCalibration();
  const AhatCamera camera(calibration);
  EXPECT_THAT(camera.rig_from_ahat(), RigidNear(calibration.rig_from_ahat, 0.0, 0.0));
  const Eigen::Vector4d k = calibration.pinhole_fx_fy_cx_cy;
  double worst_rad = 0.0;
  for (int v = 0; v < kAhatHeight; v += 3) {
    for (int u = 0; u < kAhatWidth; u += 3) {
      const Eigen::Vector2f map = calibration.undistort_map(u, v);
      ASSERT_GE(map.minCoeff(), 0.0f) << "+-55 degree pinhole lies inside the field";
      // Map entries are API coordinates: our pixel position is map - c.
      const std::optional<Eigen::Vector3d> ray =
          camera.Ray(map.cast<double>() - Eigen::Vector2d::Constant(kApiPixelCentreOffsetPx));
      ASSERT_TRUE(ray.has_value()) << u << ", " << v;
      const Eigen::Vector3d pinhole =
          Eigen::Vector3d((u - k[2]) / k[0], (v - k[3]) / k[1], 1.0).normalized();
      worst_rad = std::max(worst_rad, std::acos(std::min(1.0, ray->dot(pinhole))));
    }
  }
  EXPECT_LT(worst_rad, kInterpolatedRayTolRad);
  RecordProperty("undistort_worst_rad", std::to_string(worst_rad));
}

TEST(SyntheticAhatCalibration, UndistortMapMarksRaysBeyondTheFold) {
  SyntheticAhatOptions options;
  options.fold_radius_px = 150.0;  // field ends at 150 / 254 rad = 33.8 degrees
  const AhatCalibration calibration = MakeSyntheticAhatCalibration(options);
  EXPECT_EQ(calibration.undistort_map(0, 0), Eigen::Vector2f(-1.0f, -1.0f));  // 54.9 degrees
  EXPECT_GE(calibration.undistort_map(255, 255).minCoeff(), 0.0f);
  EXPECT_EQ(calibration.undistort_map(255 + 180, 255), Eigen::Vector2f(-1.0f, -1.0f));  // 35.3
  EXPECT_GE(calibration.undistort_map(255 + 150, 255).minCoeff(), 0.0f);  // 30.6 degrees
}

TEST(SyntheticAhatCalibration, AnglesPastNinetyDegreesAreNaNAndMasked) {
  SyntheticAhatOptions options;
  options.focal_px = 150.0;  // corners at 360 px = 2.4 rad > pi / 2
  options.fold_radius_px = 400.0;
  const AhatCalibration calibration = MakeSyntheticAhatCalibration(options);
  EXPECT_TRUE(std::isnan(calibration.uv2xy(0, 0).x()));
  const AhatCamera camera(calibration);
  EXPECT_FALSE(camera.IsValid(0, 0));
  EXPECT_TRUE(camera.IsValid(256, 256));
  EXPECT_TRUE(camera.IsValid(256, 20));  // 233 px = 1.55 rad < pi / 2
}

TEST(SyntheticAhatCalibration, OptionsCheckNamesTheField) {
  SyntheticAhatOptions options;
  options.focal_px = 0.0;
  EXPECT_THAT([&] { MakeSyntheticAhatCalibration(options); },
              testing::ThrowsMessage<PreconditionError>(testing::HasSubstr("focal_px")));
  options = {};
  options.sample_offset_px = 1.0;
  EXPECT_THAT([&] { options.Check(); },
              testing::ThrowsMessage<PreconditionError>(testing::HasSubstr("sample_offset_px")));
}

TEST(TypicalRigFromAhat, MatchesTheMeasuredDevice) {
  const Rigid3d rig_from_ahat = TypicalRigFromAhat();
  // docs/ahat.md section 10: AHAT origin (0.0212, -0.0592, 0.0118) m in the rig frame.
  EXPECT_LT((rig_from_ahat.translation - Eigen::Vector3d(21.2, -59.2, 11.8)).norm(),
            kExtrinsicsTolMm);
  const Eigen::Matrix3d rotation = rig_from_ahat.RotationMatrix();
  EXPECT_LT((rotation.col(2) - Eigen::Vector3d(0.286, -0.016, 0.958)).norm(), kAxisTol);
  EXPECT_LT((rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).norm(),
            kOrthonormalTol);
  EXPECT_NEAR(rotation.determinant(), 1.0, kOrthonormalTol);
}

}  // namespace
}  // namespace tofnav
