// SPDX-License-Identifier: BSD-3-Clause
// Predicted TRE against its closed form; refusal rules in order.
#include "tofnav/registration/registration_quality.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace tofnav {
namespace {

/// An ICP result with an isotropic information matrix and `n` inliers 10 mm apart (each in its
/// own correlation cell), centred on the origin.
IcpResult IsotropicFit(int n, double information_per_axis, double sigma_mm, Points3d& sources) {
  IcpResult icp;
  icp.converged = true;
  icp.correspondences = n;
  icp.inlier_fraction = 0.9;
  icp.rmse_mm = sigma_mm;
  icp.residual_sigma_mm = sigma_mm;
  icp.information = Matrix6d::Identity() * information_per_axis;
  icp.conditioning.rotation = icp.conditioning.translation = icp.conditioning.overall = 0.5;
  sources.clear();
  for (int i = 0; i < n; ++i) {
    sources.emplace_back(10.0 * i, 0.0, 0.0);
    icp.inlier_indices.push_back(static_cast<std::uint32_t>(i));
  }
  return icp;
}

TEST(PredictSurfaceTreMm, MatchesTheClosedForm) {
  // Cov = sigma^2 / h * I (each inlier its own cell); at lever L: var = sigma^2 / h (3 + 2 L^2).
  Points3d sources;
  const IcpResult icp = IsotropicFit(20, 400.0, 0.5, sources);
  const Eigen::Vector3d at_centre(0, 0, 0), deep(0, 60.0, 0);
  const std::vector<double> tre =
      PredictSurfaceTreMm(icp, sources, std::vector<Eigen::Vector3d>{at_centre, deep}, 5.0);
  EXPECT_NEAR(tre[0], 0.5 * std::sqrt(3.0 / 400.0), 1e-12);
  EXPECT_NEAR(tre[1], 0.5 * std::sqrt((3.0 + 2.0 * 3600.0) / 400.0), 1e-9);
}

TEST(PredictSurfaceTreMm, CorrelatedInliersCountOnce) {
  Points3d sources;
  const IcpResult icp = IsotropicFit(20, 400.0, 0.5, sources);
  const std::vector<Eigen::Vector3d> centre = {Eigen::Vector3d::Zero()};
  const double independent = PredictSurfaceTreMm(icp, sources, centre, 5.0)[0];
  // A 1 m correlation length puts all 20 inliers in one cell: 20 times the variance.
  EXPECT_NEAR(PredictSurfaceTreMm(icp, sources, centre, 1000.0)[0], independent * std::sqrt(20.0),
              1e-12);
}

TEST(PredictSurfaceTreMm, SingularInformationIsUnbounded) {
  Points3d sources;
  IcpResult icp = IsotropicFit(20, 400.0, 0.5, sources);
  icp.information(2, 2) = 0.0;  // one free rotation
  const std::vector<Eigen::Vector3d> target = {Eigen::Vector3d(0, 60, 0)};
  EXPECT_EQ(PredictSurfaceTreMm(icp, sources, target, 5.0)[0],
            std::numeric_limits<double>::infinity());
}

TEST(AssessRegistration, RefusesInOrderAndSaysWhy) {
  Points3d sources;
  const IcpResult good = IsotropicFit(20, 4000.0, 0.3, sources);  // predicted TRE 0.4 mm
  const std::vector<Eigen::Vector3d> targets = {Eigen::Vector3d(0, 60, 0)};
  EXPECT_EQ(AssessRegistration(good, sources, targets).status, RegistrationStatus::kOk);

  IcpResult low = good;
  low.inlier_fraction = 0.2;
  EXPECT_EQ(AssessRegistration(low, sources, targets).status,
            RegistrationStatus::kLowInlierFraction);
  IcpResult rough = good;
  rough.rmse_mm = 2.0;
  EXPECT_EQ(AssessRegistration(rough, sources, targets).status, RegistrationStatus::kHighRmse);
  IcpResult sliding = good;
  sliding.conditioning.rotation = 1e-4;
  const RegistrationQuality q = AssessRegistration(sliding, sources, targets);
  EXPECT_EQ(q.status, RegistrationStatus::kIllConditioned);
  EXPECT_NE(q.message.find("rotation"), std::string::npos);
  EXPECT_EQ(AssessRegistration(good, sources, targets, {}, 0.9).status,
            RegistrationStatus::kAmbiguous);
  IcpResult unsettled = good;
  unsettled.converged = false;
  EXPECT_EQ(AssessRegistration(unsettled, sources, targets).status,
            RegistrationStatus::kNotConverged);
  IcpResult empty = good;
  empty.correspondences = 0;
  EXPECT_EQ(AssessRegistration(empty, sources, targets).status, RegistrationStatus::kNoOverlap);
  RegistrationThresholds strict;
  strict.max_predicted_tre_mm = 1e-3;
  EXPECT_EQ(AssessRegistration(good, sources, targets, strict).status,
            RegistrationStatus::kHighPredictedTre);
}

// An ICP out of iterations is settled when its pose still moves by less than a tenth of a
// millimetre at the farthest target: translation plus rotation times the target's lever (60 mm).
TEST(AssessRegistration, AnIcpOutOfIterationsCountsWhenItsPoseNoLongerMovesThePlan) {
  Points3d sources;
  IcpResult creeping = IsotropicFit(20, 4000.0, 0.3, sources);
  creeping.converged = false;
  creeping.out_of_iterations = true;
  creeping.unsettled_translation_mm = 0.02;
  creeping.unsettled_rotation_rad = 1e-3;  // 0.06 mm at 60 mm: 0.08 mm in all
  const std::vector<Eigen::Vector3d> targets = {Eigen::Vector3d(0, 60, 0)};
  const RegistrationQuality settled = AssessRegistration(creeping, sources, targets);
  EXPECT_EQ(settled.status, RegistrationStatus::kOk);
  EXPECT_NEAR(settled.unsettled_mm, 0.08, 1e-12);
  creeping.unsettled_rotation_rad = 2e-3;  // 0.12 mm at the target: 0.14 in all
  const RegistrationQuality moving = AssessRegistration(creeping, sources, targets);
  EXPECT_EQ(moving.status, RegistrationStatus::kNotConverged);
  EXPECT_NE(moving.message.find("still moved 0.140 mm at a target"), std::string::npos)
      << moving.message;
  // Without targets the lever is a head's radius, 100 mm.
  EXPECT_NEAR(AssessRegistration(creeping, sources, {}).unsettled_mm, 0.22, 1e-12);
}

TEST(AmbiguityLimit, RisesWithTheIndependentSamples) {
  // A mean of squares over N independent samples has a relative standard error sqrt(2 / N): an
  // alternative is distinct when its cost exceeds the best's by 3 of them.
  const RegistrationThresholds t;
  EXPECT_DOUBLE_EQ(AmbiguityLimit(0, t), 0.7);   // unknown: the floor
  EXPECT_DOUBLE_EQ(AmbiguityLimit(20, t), 0.7);  // 1 / (1 + 0.95) = 0.51 is below the floor
  EXPECT_NEAR(AmbiguityLimit(100, t), 1.0 / (1.0 + 3.0 * std::sqrt(0.02)), 1e-12);  // 0.70
  EXPECT_NEAR(AmbiguityLimit(3000, t), 0.928, 5e-4);  // the suite's fused heads
}

TEST(AssessRegistration, AnAlternativeTheDataTellApartIsNotAmbiguous) {
  // 3000 inliers 10 mm apart: 3000 independent cells. The phantom's mirror pose in the suite
  // costs 28 % more (ratio 0.78): 11 standard errors, not ambiguous; 5 % more (0.95) is.
  Points3d sources;
  const IcpResult fit = IsotropicFit(3000, 4000.0, 0.3, sources);
  const std::vector<Eigen::Vector3d> targets = {Eigen::Vector3d(0, 60, 0)};
  const RegistrationQuality clear = AssessRegistration(fit, sources, targets, {}, 0.78, 86.0);
  EXPECT_EQ(clear.effective_samples, 3000);
  EXPECT_EQ(clear.status, RegistrationStatus::kOk);
  const RegistrationQuality close = AssessRegistration(fit, sources, targets, {}, 0.95, 86.0);
  EXPECT_EQ(close.status, RegistrationStatus::kAmbiguous);
  EXPECT_NE(close.message.find("86 mm away"), std::string::npos);
}

}  // namespace
}  // namespace tofnav
