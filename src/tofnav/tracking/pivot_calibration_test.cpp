// SPDX-License-Identifier: BSD-3-Clause
// Pivot calibration on synthetic poses: exact recovery, noise, and the refusals.
#include "tofnav/tracking/pivot_calibration.hpp"

#include <gtest/gtest.h>

#include <numbers>
#include <random>

namespace tofnav {
namespace {

const Eigen::Vector3d kTip(3.0, -2.0, -160.0);    // tip 160 mm below the marker frame
const Eigen::Vector3d kPivot(40.0, -25.0, 90.0);  // the divot, in the reference frame

// Poses of an instrument swung about the divot: the shaft tilted by up to `tilt_rad` in every
// direction and spun about itself; positions with Gaussian noise of `noise_mm`.
std::vector<Rigid3d> Swings(double tilt_rad, double noise_mm, int count, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, noise_mm);
  std::vector<Rigid3d> poses;
  for (int i = 0; i < count; ++i) {
    const double azimuth = 2.0 * std::numbers::pi * unit(rng);
    const Eigen::Quaterniond rotation =
        Eigen::AngleAxisd(tilt_rad * std::sqrt(unit(rng)),
                          Eigen::Vector3d(std::cos(azimuth), std::sin(azimuth), 0.0)) *
        Eigen::AngleAxisd(0.5 * (unit(rng) - 0.5), Eigen::Vector3d::UnitZ());
    const Eigen::Vector3d t = kPivot - rotation * kTip;  // R tip + t = pivot
    poses.emplace_back(rotation, t + Eigen::Vector3d(noise(rng), noise(rng), noise(rng)));
  }
  return poses;
}

TEST(PivotCalibration, RecoversTipAndPivotExactly) {
  constexpr double kExactMm = 1e-9;  // no noise: the least squares is exact
  const PivotCalibrationResult r = CalibratePivot(Swings(0.6, 0.0, 60, 1));
  EXPECT_EQ(r.status, PivotStatus::kOk);
  EXPECT_LT((r.tip_in_instrument - kTip).norm(), kExactMm);
  EXPECT_LT((r.pivot_in_reference - kPivot).norm(), kExactMm);
  EXPECT_LT(r.rms_mm, kExactMm);
  EXPECT_EQ(r.poses, 60u);
  // Tilts up to 0.6 rad in every direction: pairs up to ~1.2 rad apart (plus 2 x 1.3 deg: the
  // tip sits 3.6 mm off the marker frame's z axis, so the spin moves the shaft direction).
  EXPECT_GT(r.angular_range_rad, 1.0);
  EXPECT_LE(r.angular_range_rad, 1.2 + 0.05);
}

TEST(PivotCalibration, NoiseAveragesOut) {
  // 0.3 mm per-axis noise on 400 poses: the tip error shrinks with sqrt(poses) to ~0.1 mm; the
  // RMS residual reports the per-pose noise (sqrt(3) * 0.3 = 0.52 mm).
  constexpr double kMaxTipErrorMm = 0.2;
  const PivotCalibrationResult r = CalibratePivot(Swings(0.6, 0.3, 400, 2));
  EXPECT_EQ(r.status, PivotStatus::kOk);
  EXPECT_LT((r.tip_in_instrument - kTip).norm(), kMaxTipErrorMm);
  EXPECT_NEAR(r.rms_mm, 0.52, 0.08);
}

TEST(PivotCalibration, MisTrackedPosesAreDropped) {
  // 5 % of the poses 20 mm off (a swapped marker, say): dropped by the refit, the tip as without.
  constexpr double kMaxTipErrorMm = 0.2;
  std::vector<Rigid3d> poses = Swings(0.6, 0.3, 400, 5);
  for (std::size_t i = 0; i < poses.size(); i += 20) poses[i].translation.x() += 20.0;
  const PivotCalibrationResult r = CalibratePivot(poses);
  EXPECT_EQ(r.outliers, 20u);
  EXPECT_LT((r.tip_in_instrument - kTip).norm(), kMaxTipErrorMm);
  PivotCalibrationOptions keep_all;
  keep_all.outlier_factor = 0.0;
  const PivotCalibrationResult all = CalibratePivot(poses, keep_all);
  EXPECT_EQ(all.outliers, 0u);
  EXPECT_GT(all.rms_mm, 4.0 * r.rms_mm);  // sqrt(5 % x 20^2) = 4.5 mm against 0.52 mm
}

TEST(PivotCalibration, RefusesTooLittleRotationAndTooFewPoses) {
  const PivotCalibrationResult small = CalibratePivot(Swings(0.2, 0.1, 200, 3));  // <= 23 deg
  EXPECT_EQ(small.status, PivotStatus::kTooLittleRotation);
  EXPECT_LT(small.angular_range_rad, 0.5236);
  EXPECT_EQ(CalibratePivot(Swings(0.6, 0.0, 5, 4)).status, PivotStatus::kTooFewPoses);
  PivotCalibrationOptions bad;
  bad.min_poses = 1;
  EXPECT_THROW(CalibratePivot({}, bad), std::invalid_argument);
}

}  // namespace
}  // namespace tofnav
